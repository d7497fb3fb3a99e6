#include <gtest/gtest.h>
#include <contact/grid.h>
TEST(Grid, Builds) { EXPECT_EQ(contact::StructuredGrid::uniform({0,0},{1,1},{4,4}).num_nodes(), 25u); }
