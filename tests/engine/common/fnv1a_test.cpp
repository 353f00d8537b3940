// The project's one content hash against FNV-1a 64's published test vectors.
#include "engine/common/fnv1a.h"

#include <gtest/gtest.h>

namespace dispatch::engine {
namespace {

TEST(Fnv1a64, MatchesThePublishedVectors) {
  EXPECT_EQ(Fnv1a64(""), 0xcbf29ce484222325ull);  // the offset basis itself
  EXPECT_EQ(Fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(Fnv1a64("foobar"), 0x85944171f73967e8ull);
  EXPECT_EQ(Hex64(Fnv1a64("a")), "af63dc4c8601ec8c");
  EXPECT_EQ(Hex64(1), "0000000000000001");
  // Another basis gives another hash (the legacy map tag), same prime.
  EXPECT_NE(Fnv1a64("a", 1469598103934665603ull), Fnv1a64("a"));
  EXPECT_EQ(Fnv1a64("", 42), 42u);
}

}  // namespace
}  // namespace dispatch::engine
