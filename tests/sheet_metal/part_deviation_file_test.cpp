#include "twincal/sheet_metal/part_deviation_file.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/sheet_metal/part_field.hpp"

namespace twincal::part_deviation_file_test {
namespace {

class PartDeviationFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ =
        std::filesystem::temp_directory_path() /
        ("twincal_part_file_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  std::filesystem::path write_text(const std::string& name, const std::string& text) const {
    const std::filesystem::path path = directory_ / name;
    std::ofstream(path) << text;
    return path;
  }

  // The message of the InvalidArgumentError that reading `path` throws.
  std::string read_error(const std::filesystem::path& path) const {
    try {
      (void)PartDeviationFile::read(path, mesh_);
    } catch (const InvalidArgumentError& error) {
      return error.what();
    }
    return "no error";
  }

  // A 2 × 1 element mesh: nodes (0,0) (10,0) (20,0) (0,10) (10,10) (20,10).
  PlateMesh mesh_{2, 1, 10.0, 10.0};
  std::filesystem::path directory_;
};

TEST_F(PartDeviationFileTest, RoundTripIsExact) {
  const PlateMesh mesh(6, 4, 20.0, 20.0, 100.0, -40.0);
  RandomStream stream(3);
  const VectorX part = PartField(PartFieldOptions{}).sample(mesh, stream);
  const std::filesystem::path path = directory_ / "part.csv";
  PartDeviationFile::write(path, mesh, part);
  const VectorX read = PartDeviationFile::read(path, mesh);
  EXPECT_EQ(read, part);
}

TEST_F(PartDeviationFileTest, DeflectionOnlyFilesGetFiniteDifferenceSlopes) {
  // A quadratic w: the second-order differences (central and one-sided) are exact for it.
  const PlateMesh mesh(4, 3, 10.0, 10.0);
  std::string text = "# scan\nx,y,w\n";
  for (Index node = mesh.node_count() - 1; node >= 0; --node) {  // any order
    const double x = mesh.x(node);
    const double y = mesh.y(node);
    text += fmt::format("{}, {}, {}\n", x, y, 1e-3 * x * x - 2e-3 * x * y + 5e-4 * y * y + 0.1);
  }
  const VectorX read = PartDeviationFile::read(write_text("w.csv", text), mesh);
  for (Index node = 0; node < mesh.node_count(); ++node) {
    const double x = mesh.x(node);
    const double y = mesh.y(node);
    EXPECT_NEAR(read(PlateMesh::dof(node, 1)), -2e-3 * x + 1e-3 * y, 1e-12);    // ∂w/∂y
    EXPECT_NEAR(read(PlateMesh::dof(node, 2)), -(2e-3 * x - 2e-3 * y), 1e-12);  // −∂w/∂x
  }
}

TEST_F(PartDeviationFileTest, BadFilesNameTheFileLineAndRule) {
  using ::testing::HasSubstr;
  EXPECT_THAT(read_error(directory_ / "missing.csv"), HasSubstr("cannot open"));
  EXPECT_THAT(read_error(write_text("h.csv", "x,y,z\n")), HasSubstr("h.csv:1: header is 'x,y,z'"));
  EXPECT_THAT(read_error(write_text("e.csv", "# only a comment\n")), HasSubstr("no header"));
  const std::string header = "x,y,w\n";
  EXPECT_THAT(read_error(write_text("f.csv", header + "0,0\n")),
              HasSubstr("f.csv:2: row has 2 fields; rule: must have 3"));
  EXPECT_THAT(read_error(write_text("n.csv", header + "0,0,abc\n")),
              HasSubstr("field 3 is 'abc'; rule: must be a finite number"));
  EXPECT_THAT(read_error(write_text("i.csv", header + "0,0,inf\n")), HasSubstr("finite number"));
  EXPECT_THAT(read_error(write_text("p.csv", header + "5,0,0.1\n")),
              HasSubstr("p.csv:2: point (5, 0) is not a mesh node"));
  EXPECT_THAT(read_error(write_text("d.csv", header + "0,0,0.1\n0,0,0.2\n")),
              HasSubstr("d.csv:3: node at (0, 0) appears again"));
  EXPECT_THAT(read_error(write_text("c.csv", header + "0,0,0.1\n10,0,0.2\n")),
              HasSubstr("has 2 node rows; rule: must have one per node (6)"));
  std::string full = header;
  for (Index node = 0; node < mesh_.node_count(); ++node) {
    full += fmt::format("{},{},0.5\n", mesh_.x(node), mesh_.y(node));
  }
  EXPECT_EQ(read_error(write_text("ok.csv", full)), "no error");
}

TEST_F(PartDeviationFileTest, ReadsAStreamAsItReadsAFileNamingTheGivenName) {
  std::string text = "x,y,w\n";
  for (Index node = 0; node < mesh_.node_count(); ++node) {
    text +=
        fmt::format("{},{},{}\n", mesh_.x(node), mesh_.y(node), 0.1 * static_cast<double>(node));
  }
  std::istringstream in(text);
  EXPECT_EQ(PartDeviationFile::read(in, "scan 42", mesh_),
            PartDeviationFile::read(write_text("s.csv", text), mesh_));
  std::istringstream bad("x,y,w\n0,0,nan\n");
  try {
    (void)PartDeviationFile::read(bad, "scan 42", mesh_);
    FAIL() << "a NaN deviation was read";
  } catch (const InvalidArgumentError& error) {
    EXPECT_EQ(error.argument(), "scan 42");
    EXPECT_THAT(error.what(), ::testing::HasSubstr("scan 42:2: field 3 is 'nan'"));
  }
}

TEST_F(PartDeviationFileTest, WriteChecksTheSize) {
  EXPECT_THROW(PartDeviationFile::write(directory_ / "x.csv", mesh_, VectorX::Zero(5)),
               DimensionMismatchError);
}

}  // namespace
}  // namespace twincal::part_deviation_file_test
