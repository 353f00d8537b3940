// Text placed in XML (the SVG renderers): &, <, >, " and ' as entities.
#pragma once

#include <string>
#include <string_view>

namespace dispatch::engine {

std::string XmlEscape(std::string_view text);

}  // namespace dispatch::engine
