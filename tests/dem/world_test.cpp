#include <gtest/gtest.h>
TEST(WorldT, Placeholder) {}
