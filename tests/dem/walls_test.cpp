#include <gtest/gtest.h>
TEST(Walls, Placeholder) {}
