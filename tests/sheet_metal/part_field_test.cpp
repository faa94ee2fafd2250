#include "twincal/sheet_metal/part_field.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "twincal/core/error.hpp"

namespace twincal::part_field_test {
namespace {

TEST(PartField, SlopesAreTheDerivativesOfTheDeflection) {
  const PlateMesh mesh(40, 30, 2.0, 2.0, 50.0, 20.0);
  RandomStream stream(17);
  const VectorX part = PartField(PartFieldOptions{}).sample(mesh, stream);
  // Central differences (error O(h²) ~ 1e-7 of the slopes here) at interior nodes.
  double largest = 0.0;
  double error = 0.0;
  for (Index j = 1; j < 30; ++j) {
    for (Index i = 1; i < 40; ++i) {
      const Index node = mesh.node(i, j);
      const auto w = [&](Index a, Index b) { return part(PlateMesh::dof(mesh.node(a, b), 0)); };
      const double wx = (w(i + 1, j) - w(i - 1, j)) / 4.0;
      const double wy = (w(i, j + 1) - w(i, j - 1)) / 4.0;
      error = std::max({error, std::abs(part(PlateMesh::dof(node, 1)) - wy),
                        std::abs(part(PlateMesh::dof(node, 2)) + wx)});
      largest = std::max({largest, std::abs(wx), std::abs(wy)});
    }
  }
  EXPECT_LT(error, 1e-3 * largest);
}

TEST(PartField, VarianceMatchesTheKernelAndStreamsAreReproducible) {
  PartFieldOptions options;
  options.bow = 0.0;
  options.twist = 0.0;
  const PartField field(options);
  const PlateMesh mesh(2, 2, 100.0, 100.0);
  double sum_squares = 0.0;
  double product = 0.0;  // nodes 0 and 1 are 100 mm apart
  constexpr int samples = 400;
  for (int s = 0; s < samples; ++s) {
    RandomStream stream = RandomStream(1).substream(static_cast<std::uint64_t>(s));
    const VectorX part = field.sample(mesh, stream);
    sum_squares += part(0) * part(0);
    product += part(0) * part(PlateMesh::dof(1, 0));
  }
  const double variance = options.standard_deviation * options.standard_deviation;
  EXPECT_NEAR(sum_squares / samples, variance, 0.25 * variance);
  const double correlation = std::exp(-100.0 * 100.0 / (2.0 * 150.0 * 150.0));
  EXPECT_NEAR(product / samples, variance * correlation, 0.25 * variance);

  RandomStream a(9);
  RandomStream b(9);
  RandomStream c(10);
  const VectorX first = field.sample(mesh, a);
  EXPECT_EQ(first, field.sample(mesh, b));
  EXPECT_NE(first, field.sample(mesh, c));
}

TEST(PartField, RejectsBadOptions) {
  PartFieldOptions options;
  options.correlation_length = 0.0;
  EXPECT_THROW(PartField{options}, InvalidArgumentError);
  options = {};
  options.features = 0;
  EXPECT_THROW(PartField{options}, InvalidArgumentError);
  options = {};
  options.bow = -1.0;
  EXPECT_THROW(PartField{options}, InvalidArgumentError);
}

}  // namespace
}  // namespace twincal::part_field_test
