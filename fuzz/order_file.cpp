// The order files wmsctl reads (clients/order_file.h): seed task tables (CSV) and JSON orders.
// The first byte picks the format; any text gives orders or an error naming the problem.
#include <cstdlib>

#include "clients/order_file.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool json = data[0] & 1;
  const auto file = dispatch::clients::ParseOrderText(dispatch::fuzz::Text(data + 1, size - 1), json, "f-");
  if (!file.ok() && file.error.empty()) std::abort();  // an error always says what
  return 0;
}
