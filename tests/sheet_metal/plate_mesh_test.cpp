#include "twincal/sheet_metal/plate_mesh.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal::plate_mesh_test {
namespace {

TEST(PlateMesh, NumbersNodesRowByRow) {
  const PlateMesh mesh(3, 2, 10.0, 20.0, 5.0, -10.0);
  EXPECT_EQ(mesh.node_count(), 12);
  EXPECT_EQ(mesh.dof_count(), 36);
  EXPECT_EQ(mesh.node(1, 2), 9);
  EXPECT_EQ(mesh.column_of(9), 1);
  EXPECT_EQ(mesh.row_of(9), 2);
  EXPECT_DOUBLE_EQ(mesh.x(9), 15.0);
  EXPECT_DOUBLE_EQ(mesh.y(9), 30.0);
  EXPECT_EQ(PlateMesh::dof(9, 2), 29);
  const Eigen::Matrix<Index, 4, 1> corners = mesh.element_nodes(2, 1);
  EXPECT_EQ(corners(0), 6);
  EXPECT_EQ(corners(1), 7);
  EXPECT_EQ(corners(2), 11);
  EXPECT_EQ(corners(3), 10);
}

TEST(PlateMesh, FindsNodesAndRejectsOtherPoints) {
  const PlateMesh mesh(3, 2, 10.0, 20.0, 5.0, -10.0);
  EXPECT_EQ(mesh.find_node(25.0, 10.0), mesh.node(2, 1));
  EXPECT_EQ(mesh.find_node(25.0, 10.0 + 1e-9), mesh.node(2, 1));
  EXPECT_FALSE(mesh.find_node(20.0, 10.0).has_value());  // between nodes
  EXPECT_FALSE(mesh.find_node(45.0, 10.0).has_value());  // outside
  EXPECT_TRUE(mesh.contains(35.0, 30.0));
  EXPECT_FALSE(mesh.contains(35.1, 30.0));
  try {
    (void)mesh.node_at(20.0, 10.0, "locator L1");
    ADD_FAILURE() << "no error";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "locator L1");
    EXPECT_THAT(error.what(), ::testing::HasSubstr("point (20, 10) mm is not a node"));
  }
  EXPECT_THROW(PlateMesh(0, 2, 1.0, 1.0), InvalidArgumentError);
  EXPECT_THROW(PlateMesh(1, 2, -1.0, 1.0), InvalidArgumentError);
}

}  // namespace
}  // namespace twincal::plate_mesh_test
