#pragma once
/// @file
/// `draw_candidates`: the paper's candidate controls for the look-ahead minimization, eq. (14)
/// (Sec. 2.3.2): points of a Sampler mapped to N(û*, P) by a GaussianTransform, those outside
/// the box U_t disregarded. With `keep_drawing`, further batches of the same size are drawn
/// until `count` candidates survive or `max_batches` batches have been drawn; a batch of 2^m
/// Sobol points then continues the sequence in aligned blocks, keeping the balance property.
/// The result reports how many points were drawn and how many survived, so a caller sees an
/// incomplete set (a box far out in the tails of N(û*, P)) instead of silently getting fewer
/// candidates.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <Eigen/Core>

#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"
#include "twincal/core/validate.hpp"
#include "twincal/samplers/box_set.hpp"
#include "twincal/samplers/gaussian_transform.hpp"
#include "twincal/samplers/sampler.hpp"

namespace twincal {

struct CandidateOptions {
  /// Points per batch and the number of candidates wanted (the paper: 2^(2+d)).
  Index count = 32;
  /// Draw further batches until `count` candidates survive (the paper draws one batch).
  bool keep_drawing = false;
  /// Bound on the batches drawn with keep_drawing.
  Index max_batches = 64;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem({rule::at_least("count", count, Index{1}),
                          rule::at_least("max_batches", max_batches, Index{1})});
  }
};

/// Candidates inside the box, with the counts that say how they were obtained. A set can be
/// redrawn in place (`draw`), reusing its buffers: with a fixed N and an unchanged count, a
/// redraw allocates nothing, so a controller can keep one set per dimension across steps.
template <int N>
class CandidateSet {
 public:
  using Points = Matrix<N, Dynamic>;

  /// The candidates, one per column in drawing order: the first size() points drawn inside the
  /// box.
  [[nodiscard]] Eigen::Ref<const Points> points() const { return buffer_.leftCols(size()); }
  /// Number of candidates, min(survived, requested).
  [[nodiscard]] Index size() const noexcept { return std::min(survived_, requested_); }
  /// CandidateOptions::count of the last draw.
  [[nodiscard]] Index requested() const noexcept { return requested_; }
  /// Points taken from the sampler.
  [[nodiscard]] Index drawn() const noexcept { return drawn_; }
  /// Drawn points that fell inside the box (may exceed requested() within the last batch).
  [[nodiscard]] Index survived() const noexcept { return survived_; }
  /// True when requested() candidates survived.
  [[nodiscard]] bool complete() const noexcept { return survived_ >= requested_; }

  /// Replaces the set by a new draw (see the file comment). Throws InvalidArgumentError for
  /// invalid options and DimensionMismatchError unless sampler, transform and box have one
  /// dimension; neither the set nor the sampler changes when it throws before drawing.
  template <Sampler S>
  void draw(S& sampler, const GaussianTransform<N>& transform, const BoxSet<N>& box,
            const CandidateOptions& options = {}) {
    require_valid("options", options);
    const Index d = transform.dimension();
    require_dimension("sampler", static_cast<Index>(sampler.dimension()), d, "dimension");
    require_dimension("box", box.dimension(), d, "dimension");

    const Index count = options.count;
    buffer_.resize(d, count);  // no-ops when the size is unchanged
    mapped_.resize(d, count);
    uniform_.resize(d, count);
    requested_ = count;
    drawn_ = 0;
    survived_ = 0;
    const Index batches = options.keep_drawing ? options.max_batches : 1;
    for (Index b = 0; b < batches && survived_ < count; ++b) {
      sampler.fill(uniform_);
      transform.transform(uniform_, mapped_);
      const Index kept = box.keep_inside(mapped_);
      const Index stored = std::min(kept, count - survived_);
      buffer_.middleCols(survived_, stored) = mapped_.leftCols(stored);
      drawn_ += count;
      survived_ += kept;
    }
  }

 private:
  Points buffer_;   // requested columns; the first size() hold the candidates
  Points mapped_;   // one batch after the transform
  Points uniform_;  // one batch from the sampler (fixed rows map into Ref<MatrixX>)
  Index requested_ = 0;
  Index drawn_ = 0;
  Index survived_ = 0;
};

/// Draws a new candidate set (CandidateSet::draw into a fresh set).
template <Sampler S, int N>
[[nodiscard]] CandidateSet<N> draw_candidates(S& sampler, const GaussianTransform<N>& transform,
                                              const BoxSet<N>& box,
                                              const CandidateOptions& options = {}) {
  CandidateSet<N> set;
  set.draw(sampler, transform, box, options);
  return set;
}

}  // namespace twincal
