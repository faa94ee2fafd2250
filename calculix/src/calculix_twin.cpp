#include "twincal/calculix/calculix_twin.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "twincal/calculix/calculix_process.hpp"
#include "twincal/calculix/calculix_results.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/validate.hpp"

namespace twincal {
namespace {

// The normal deviations w of (w, θx, θy) nodal vectors, or the vector itself when it holds w
// only: the part fields and part files give all three, the CalculiX model needs w.
VectorX normal_deviations(const VectorX& part, Index nodes) {
  if (part.size() == 3 * nodes) {
    VectorX w(nodes);
    for (Index i = 0; i < nodes; ++i) w(i) = part(3 * i);
    return w;
  }
  return part;
}

// Removes a scratch directory when the evaluation ends, however it ends.
class ScratchDirectory {
 public:
  ScratchDirectory(std::filesystem::path path, bool keep) : path_(std::move(path)), keep_(keep) {
    std::filesystem::create_directories(path_);
  }
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;
  ~ScratchDirectory() {
    if (keep_) return;
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }

 private:
  std::filesystem::path path_;
  bool keep_;
};

}  // namespace

CalculixTwin::CalculixTwin(SheetMetalLayout layout, CalculixOptions options,
                           std::vector<VectorX> upper_parts, std::vector<VectorX> lower_parts)
    : model_(std::make_shared<const CalculixModel>(std::move(layout), std::move(options))),
      jobs_(std::make_shared<std::atomic<std::uint64_t>>(0)) {
  if (upper_parts.empty() || lower_parts.empty()) {
    throw InvalidArgumentError("parts", fmt::format("parts: {} upper and {} lower; rule: at "
                                                    "least one of each",
                                                    upper_parts.size(), lower_parts.size()));
  }
  const Index upper_nodes = model_->mesh(SheetMetalPart::upper).node_count();
  const Index lower_nodes = model_->mesh(SheetMetalPart::lower).node_count();
  for (const VectorX& part : upper_parts) {
    upper_parts_.push_back(normal_deviations(part, upper_nodes));
  }
  for (const VectorX& part : lower_parts) {
    lower_parts_.push_back(normal_deviations(part, lower_nodes));
  }
  for (const VectorX& upper : upper_parts_) model_->require_parts({upper, lower_parts_.front()});
  for (const VectorX& lower : lower_parts_) model_->require_parts({upper_parts_.front(), lower});
  for (const LayoutPoint& locator : model_->layout().locators) {
    locator_names_.push_back(locator.name);
  }
  const double bound = model_->options().locator_bound;
  lower_bounds_ = VectorX::Constant(control_dimension(), -bound);
  upper_bounds_ = VectorX::Constant(control_dimension(), bound);
}

CalculixTwin CalculixTwin::generate(SheetMetalLayout layout, CalculixOptions options,
                                    std::uint64_t seed, Index upper_parts, Index lower_parts,
                                    const PartFieldOptions& field_options) {
  const CalculixModel model(layout, options);  // validates and refines before sampling
  const PartField field(field_options);
  const RandomStream root(seed);
  return {std::move(layout), std::move(options),
          field.sample_parts(model.mesh(SheetMetalPart::upper), root, "upper", upper_parts),
          field.sample_parts(model.mesh(SheetMetalPart::lower), root, "lower", lower_parts)};
}

CalculixParts CalculixTwin::parts(const AssemblyId& assembly) const {
  if (assembly.upper < 0 || assembly.upper >= upper_part_count() || assembly.lower < 0 ||
      assembly.lower >= lower_part_count()) {
    throw InvalidArgumentError(
        "assembly", fmt::format("assembly: {}; rule: upper in [0, {}), lower in [0, {})", assembly,
                                upper_part_count(), lower_part_count()));
  }
  return {upper_parts_[static_cast<std::size_t>(assembly.upper)],
          lower_parts_[static_cast<std::size_t>(assembly.lower)]};
}

double CalculixTwin::quality(const AssemblyId& assembly,
                             const Eigen::Ref<const VectorX>& control) const {
  require_control(control, control_dimension());
  VectorX out(1);
  quality_batch(assembly, control, out);
  return out(0);
}

void CalculixTwin::quality_batch(const AssemblyId& assembly,
                                 const Eigen::Ref<const MatrixX>& controls,
                                 Eigen::Ref<VectorX> out) const {
  const CalculixParts assembly_parts = parts(assembly);
  evaluate(assembly_parts, controls, out, fmt::format("assembly {}", assembly));
}

Index CalculixTwin::key_point_count() const noexcept { return model_->key_point_count(); }

void CalculixTwin::deviations_batch(const AssemblyId& assembly,
                                    const Eigen::Ref<const MatrixX>& controls,
                                    Eigen::Ref<MatrixX> out) const {
  require_deviations_batch(controls, out, control_dimension(), key_point_count());
  const CalculixParts assembly_parts = parts(assembly);
  key_deviations(assembly_parts, controls, out, fmt::format("assembly {}", assembly));
}

CalculixBatchSummary CalculixTwin::evaluate(const CalculixParts& parts,
                                            const Eigen::Ref<const MatrixX>& controls,
                                            Eigen::Ref<VectorX> out, std::string_view label) const {
  require_dimension("out", out.size(), controls.cols());
  MatrixX deviations(model_->key_point_count(), controls.cols());
  CalculixBatchSummary summary = key_deviations(parts, controls, deviations, label);
  const double scale = 1.0 / std::sqrt(static_cast<double>(model_->key_point_count()));
  out = scale * deviations.colwise().norm().transpose();  // NaN columns stay NaN
  return summary;
}

CalculixBatchSummary CalculixTwin::key_deviations(const CalculixParts& parts,
                                                  const Eigen::Ref<const MatrixX>& controls,
                                                  Eigen::Ref<MatrixX> out,
                                                  std::string_view label) const {
  model_->require_parts(parts);
  model_->require_controls(controls);
  require_dimension("out (rows)", out.rows(), model_->key_point_count());
  require_dimension("out (columns)", out.cols(), controls.cols());
  const CalculixOptions& options = model_->options();
  const ScratchDirectory scratch(
      options.scratch_root / fmt::format("twincal-calculix-{}-{}", ::getpid(), (*jobs_)++),
      options.keep_files);
  CalculixBatchSummary summary;
  const Index count = controls.cols();
  const auto solve = [&](Index first, Index columns) {
    const std::string job = fmt::format("columns-{}-{}", first, first + columns - 1);
    const CalculixRun run = run_calculix(options, scratch.path(), job,
                                         model_->deck(parts, controls.middleCols(first, columns)));
    ++summary.solver_runs;
    summary.solver_seconds += run.seconds;
    const std::optional<CalculixFailure> failure = classify(run);
    if (failure && *failure != CalculixFailure::no_convergence) {
      throw CalculixError(
          *failure,
          fmt::format("calculix: {} for {}, columns {} to {}; the solver's "
                      "log ends:\n{}",
                      to_string(*failure), label, first, first + columns - 1, log_tail(run.log)),
          log_tail(run.log));
    }
    const std::vector<NodePrint> releases = release_prints(read_displacement_prints(run.dat));
    const Index done = std::min<Index>(static_cast<Index>(releases.size()), columns);
    if (done < columns && !failure) {
      throw CalculixError(CalculixFailure::unreadable_results,
                          fmt::format("calculix: {}: {} of {} columns printed by a run that "
                                      "reported success",
                                      label, done, columns),
                          log_tail(run.log));
    }
    for (Index c = 0; c < done; ++c) {
      out.col(first + c) = model_->key_deviations(parts, releases[static_cast<std::size_t>(c)]);
    }
    return std::pair{done, failure ? log_tail(run.log) : std::string()};
  };
  Index next = 0;
  while (next < count) {
    auto [done, log] = solve(next, count - next);
    next += done;
    if (next == count) break;
    // Column `next` failed after others converged before it in the deck: once more alone,
    // from the undeformed state (a column first in its deck already started from there).
    if (done > 0) {
      auto [alone, alone_log] = solve(next, 1);
      if (alone == 1) {
        ++next;
        continue;
      }
      log = std::move(alone_log);
    }
    std::string control;
    for (Index k = 0; k < controls.rows(); ++k) {
      control += fmt::format("{}{}", k == 0 ? "" : ", ", controls(k, next));
    }
    out.col(next).setConstant(std::numeric_limits<double>::quiet_NaN());
    summary.failed.push_back(next);
    summary.last_failure = fmt::format(
        "calculix: {}, column {} (u = [{}]): no convergence; the solver's log "
        "ends:\n{}",
        label, next, control, log);
    ++next;
  }
  return summary;
}

}  // namespace twincal
