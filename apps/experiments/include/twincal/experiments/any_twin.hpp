#pragma once
/// @file
/// `AnyTwin`: a type-erased twin with a known optimum over AssemblyId (models/twin.hpp's
/// TwinWithOptimum): the FEM sheet-metal twin, the analytic twins or a user's, behind one type,
/// so the episode runner is compiled once per controller and not once per twin. Only the batch
/// call crosses the virtual boundary, once per filter update or candidate grid, so the erasure
/// costs nothing measurable. Copies share the twin; the only change a twin takes is a scanned
/// assembly registered (add_scanned()), which copies then share too.

#include <array>
#include <concepts>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "twincal/core/eigen.hpp"
#include "twincal/experiments/scanned_assembly.hpp"
#include "twincal/models/assembly_id.hpp"
#include "twincal/models/twin.hpp"

namespace twincal {

/// What searching u0(x) (eq. 3) cost a twin that searches it (SearchedOptimumTwin,
/// ExternalCaseTwin): its evaluations and requests over the assemblies it searched.
struct OptimumSearchCost {
  std::uint64_t evaluations = 0;
  /// Calls of the twin: batches for the batched searches, one per evaluation otherwise.
  std::uint64_t requests = 0;
  Index assemblies = 0;
  /// The optima were read from the file that search wrote (ExternalTwinSettings::optima_file):
  /// the cost is the search's then, not this study's.
  bool read = false;
};

class AnyTwin {
 public:
  using Assembly = AssemblyId;

  /// Wraps `twin` (moved in). `assemblies` lists the twin's assemblies (all of them, in the
  /// twin's order); `significant` names the locators A, B, C (fewer when d < 3).
  template <TwinWithOptimum T>
  requires std::same_as<typename T::Assembly, AssemblyId> AnyTwin(
      T twin, std::vector<AssemblyId> assemblies, std::vector<Index> significant)
      : model_(std::make_shared<Model<T>>(std::move(twin))),
        assemblies_(std::move(assemblies)),
        significant_(std::move(significant)) {}

  [[nodiscard]] Index control_dimension() const { return model_->control_dimension(); }
  [[nodiscard]] const std::vector<std::string>& locator_names() const {
    return model_->locator_names();
  }
  [[nodiscard]] const VectorX& lower_bounds() const { return model_->lower_bounds(); }
  [[nodiscard]] const VectorX& upper_bounds() const { return model_->upper_bounds(); }
  [[nodiscard]] double quality(const AssemblyId& assembly,
                               const Eigen::Ref<const VectorX>& control) const {
    return model_->quality(assembly, control);
  }
  void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                     Eigen::Ref<VectorX> out) const {
    model_->quality_batch(assembly, controls, out);
  }
  [[nodiscard]] VectorX optimum(const AssemblyId& assembly) const {
    return model_->optimum(assembly);
  }
  [[nodiscard]] double optimal_quality(const AssemblyId& assembly) const {
    return model_->optimal_quality(assembly);
  }
  /// m, the key points of a twin that answers its deviations (TwinWithDeviations); 0 for one
  /// that answers only Q.
  [[nodiscard]] Index key_point_count() const { return model_->key_point_count(); }
  /// out.col(j) = r(x, controls.col(j)), m × k.
  /// @throws InvalidArgumentError (field "deviations") for a twin that answers only Q; the
  ///         twin's errors.
  void deviations_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                        Eigen::Ref<MatrixX> out) const {
    model_->deviations_batch(assembly, controls, out);
  }
  /// Registers the assembly of scanned `parts` with a twin that takes them (T::add_scanned,
  /// e.g. ExternalCaseTwin; with `known`, its optimum as found before) and returns its id; not
  /// for use concurrent with other calls.
  /// @throws InvalidArgumentError (field "parts") for a twin whose assemblies are only its own
  ///         part indices; the twin's errors, with nothing registered.
  AssemblyId add_scanned(const nlohmann::json& parts,
                         const std::optional<ScannedOptimum>& known = std::nullopt) {
    return model_->add_scanned(parts, known);
  }
  /// What the twin's u0 searches cost so far; nothing for a twin that knows its optimum.
  [[nodiscard]] std::optional<OptimumSearchCost> optimum_search() const {
    return model_->optimum_search();
  }
  /// The twin's own assemblies (pairs of part indices), not the scanned ones.
  [[nodiscard]] const std::vector<AssemblyId>& assemblies() const noexcept { return assemblies_; }
  /// Indices of the locators A, B, C (the ones that affect the quality most).
  [[nodiscard]] const std::vector<Index>& significant_locators() const noexcept {
    return significant_;
  }

 private:
  struct Concept {
    virtual ~Concept() = default;
    [[nodiscard]] virtual Index control_dimension() const = 0;
    [[nodiscard]] virtual const std::vector<std::string>& locator_names() const = 0;
    [[nodiscard]] virtual const VectorX& lower_bounds() const = 0;
    [[nodiscard]] virtual const VectorX& upper_bounds() const = 0;
    [[nodiscard]] virtual double quality(const AssemblyId&,
                                         const Eigen::Ref<const VectorX>&) const = 0;
    virtual void quality_batch(const AssemblyId&, const Eigen::Ref<const MatrixX>&,
                               Eigen::Ref<VectorX>) const = 0;
    [[nodiscard]] virtual Index key_point_count() const = 0;
    virtual void deviations_batch(const AssemblyId&, const Eigen::Ref<const MatrixX>&,
                                  Eigen::Ref<MatrixX>) const = 0;
    [[nodiscard]] virtual VectorX optimum(const AssemblyId&) const = 0;
    [[nodiscard]] virtual double optimal_quality(const AssemblyId&) const = 0;
    virtual AssemblyId add_scanned(const nlohmann::json& parts,
                                   const std::optional<ScannedOptimum>& known) = 0;
    [[nodiscard]] virtual std::optional<OptimumSearchCost> optimum_search() const = 0;
  };

  template <typename T>
  struct Model final : Concept {
    explicit Model(T t) : twin(std::move(t)) {}
    [[nodiscard]] Index control_dimension() const override { return twin.control_dimension(); }
    [[nodiscard]] const std::vector<std::string>& locator_names() const override {
      return twin.locator_names();
    }
    [[nodiscard]] const VectorX& lower_bounds() const override { return twin.lower_bounds(); }
    [[nodiscard]] const VectorX& upper_bounds() const override { return twin.upper_bounds(); }
    [[nodiscard]] double quality(const AssemblyId& assembly,
                                 const Eigen::Ref<const VectorX>& control) const override {
      return twin.quality(assembly, control);
    }
    void quality_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                       Eigen::Ref<VectorX> out) const override {
      twin.quality_batch(assembly, controls, out);
    }
    [[nodiscard]] Index key_point_count() const override {
      if constexpr (TwinWithDeviations<T>) {
        return twin.key_point_count();
      } else {
        return 0;
      }
    }
    void deviations_batch(const AssemblyId& assembly, const Eigen::Ref<const MatrixX>& controls,
                          Eigen::Ref<MatrixX> out) const override {
      if constexpr (TwinWithDeviations<T>) {
        twin.deviations_batch(assembly, controls, out);
      } else {
        throw_without_deviations();
      }
    }
    [[nodiscard]] VectorX optimum(const AssemblyId& assembly) const override {
      return twin.optimum(assembly);
    }
    [[nodiscard]] double optimal_quality(const AssemblyId& assembly) const override {
      return twin.optimal_quality(assembly);
    }
    AssemblyId add_scanned(const nlohmann::json& parts,
                           const std::optional<ScannedOptimum>& known) override {
      if constexpr (requires {
                      { twin.add_scanned(parts, known) } -> std::same_as<AssemblyId>;
                    }) {
        return twin.add_scanned(parts, known);
      } else {
        throw_without_scanned_parts();
      }
    }
    [[nodiscard]] std::optional<OptimumSearchCost> optimum_search() const override {
      if constexpr (requires { twin.search_evaluations(); }) {
        OptimumSearchCost cost{.evaluations = twin.search_evaluations(),
                               .requests = twin.search_evaluations(),
                               .assemblies = std::ssize(twin.assemblies())};
        if constexpr (requires { twin.search_requests(); }) cost.requests = twin.search_requests();
        if constexpr (requires { twin.scanned_count(); }) cost.assemblies += twin.scanned_count();
        if constexpr (requires { twin.optima_read(); }) cost.read = twin.optima_read();
        return cost;
      } else {
        return std::nullopt;
      }
    }
    T twin;
  };

  [[noreturn]] static void throw_without_scanned_parts();
  [[noreturn]] static void throw_without_deviations();

  std::shared_ptr<Concept> model_;
  std::vector<AssemblyId> assemblies_;
  std::vector<Index> significant_;
};

static_assert(TwinWithOptimum<AnyTwin>);

}  // namespace twincal
