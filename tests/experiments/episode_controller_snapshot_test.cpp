// Snapshots of every controller the experiments build (make_episode_controller, through
// AnyController::save / restore): a controller built with the same arguments and restored from a
// snapshot — after the snapshot went through text, as `twincal serve` stores it — goes on bit for
// bit like the original, and a bad snapshot is refused with a typed error naming the field, the
// controller unchanged.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "twincal/controllers/any_controller.hpp"
#include "twincal/controllers/exploration_kind.hpp"
#include "twincal/core/error.hpp"
#include "twincal/core/random_stream.hpp"
#include "twincal/experiments/case_twin.hpp"
#include "twincal/experiments/controller_spec.hpp"
#include "twincal/experiments/episode_runner.hpp"
#include "twincal/experiments/experiment_choices.hpp"
#include "twincal/experiments/experiment_config.hpp"
#include "twincal/experiments/twin_cases.hpp"
#include "twincal/filters/filter_scheme.hpp"
#include "twincal/models/bouncing_drift.hpp"
#include "twincal/samplers/candidate_sampler.hpp"

namespace twincal {
namespace {

using nlohmann::json;

// --- the cases --------------------------------------------------------------------------------

struct SnapshotCase {
  std::string name;  // the test's name: the controller label and what differs from the default
  ExperimentConfig config;
  ControllerSpec controller;
  Index before = 25;  // assemblies before the snapshot
  Index after = 25;   // and after it

  friend void PrintTo(const SnapshotCase& c, std::ostream* out) { *out << c.name; }
};

ExperimentConfig analytic_config(Index d) {
  ExperimentConfig config;
  config.twin_case = TwinCase::analytic;
  config.analytic_dimension = d;
  config.locators = "all";
  config.plant_noise_variance = 1e-6;  // a noisy plant: the innovations are not all alike
  config.drift_step = 0.05;
  return config;
}

// A test name from a label and what differs ("w=0.5" → "w_0_5").
std::string case_name(std::string text) {
  for (char& c : text) {
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9'))) c = '_';
  }
  return text;
}

void add_case(std::vector<SnapshotCase>& cases, const std::string& what,
              const ExperimentConfig& config, const ControllerSpec& controller) {
  cases.push_back(
      {case_name(what + "_" + controller.label()), config, controller, Index{25}, Index{25}});
}

// Every controller label the experiments know, over every filter, sampler and loss, on the
// analytic twin at d = 3 (the fixed-size instantiations) and d = 2 (dynamic size); d = 1; the
// active controller where its model fails (non-quadratic twins, a plant that is not the twin)
// and over a history that fills its ring; and the body's FEM twin.
std::vector<SnapshotCase> snapshot_cases() {
  std::vector<SnapshotCase> cases;
  const ControllerSpec w = ControllerSpec::lookahead(0.5);
  for (const Index d : {Index{3}, Index{2}}) {
    const std::string at = "d" + std::to_string(d);
    const ExperimentConfig base = analytic_config(d);
    for (const ControllerSpec& spec :
         {ControllerSpec::baseline(), ControllerSpec::nominal(), ControllerSpec::lookahead(0.0),
          ControllerSpec::lookahead(1.0), ControllerSpec::per_component(0.5),
          ControllerSpec::active()}) {
      add_case(cases, at, base, spec);
    }
    for (const FilterScheme filter :
         {FilterScheme::merwe, FilterScheme::julier, FilterScheme::cubature,
          FilterScheme::fifth_degree, FilterScheme::simplex}) {
      ExperimentConfig config = base;
      config.filter = filter;
      if (filter == FilterScheme::julier) config.kappa = 1.0;
      const std::string what = at + "_" + std::string(to_string(filter));
      add_case(cases, what, config, ControllerSpec::default_controller());
      add_case(cases, what, config, w);
      if (filter == FilterScheme::simplex) {
        // Its default controller loses P's definiteness within some 40 assemblies: snapshot
        // it early, and its failure must come back at the same step.
        cases[cases.size() - 2].before = 10;
        cases[cases.size() - 2].after = 60;
      }
    }
    for (const CandidateSampler sampler :
         {CandidateSampler::halton, CandidateSampler::random, CandidateSampler::latin_hypercube}) {
      ExperimentConfig config = base;
      config.sampler = sampler;
      add_case(cases, at + "_" + std::string(to_string(sampler)), config, w);
    }
    for (const ExplorationKind loss : {ExplorationKind::weighted_trace, ExplorationKind::log_det,
                                       ExplorationKind::max_eigenvalue}) {
      ExperimentConfig config = base;
      config.exploration = loss;
      add_case(cases, at + "_" + std::string(to_string(loss)), config, w);
    }
  }
  // Further batches until the candidates survive a narrow box (the sampler moves on further).
  ExperimentConfig narrow = analytic_config(3);
  narrow.keep_drawing = true;
  narrow.box_half_width = 0.01;
  add_case(cases, "d3_keep_drawing", narrow, w);
  add_case(
      cases, "d3_keep_drawing_halton",
      [&] {
        ExperimentConfig config = narrow;
        config.sampler = CandidateSampler::halton;
        return config;
      }(),
      w);
  for (const ControllerSpec& spec : {ControllerSpec::default_controller(), w}) {
    add_case(cases, "d1", analytic_config(1), spec);
    ExperimentConfig cubature = analytic_config(1);
    cubature.filter = FilterScheme::cubature;
    add_case(cases, "d1_cubature", cubature, spec);
  }
  // The active controller where Q² is not a quadratic: sigma-point mode, weighed model errors,
  // relinearization of kept assemblies, the do-no-harm audit.
  for (const Nonlinearity nonlinearity :
       {Nonlinearity::contact, Nonlinearity::stiffening, Nonlinearity::kink}) {
    ExperimentConfig config = analytic_config(3);
    config.nonlinearity = nonlinearity;
    add_case(cases, "d3_" + std::string(to_string(nonlinearity)), config, ControllerSpec::active());
  }
  ExperimentConfig other_plant = analytic_config(3);
  other_plant.plant_nonlinearity = Nonlinearity::contact;
  add_case(cases, "d3_contact_plant", other_plant, ControllerSpec::active());
  add_case(cases, "d3_contact_plant", other_plant, w);
  // A history longer than the estimator's ring (max_history = 128) with changes of velocity.
  ExperimentConfig bouncing = analytic_config(3);
  bouncing.drift_step = 0.1;
  bouncing.drift_bound = 0.3;
  cases.push_back({"d3_long_active", bouncing, ControllerSpec::active(), 150, 30});
  cases.push_back({"d3_long_active_kink",
                   [&] {
                     ExperimentConfig config = bouncing;
                     config.nonlinearity = Nonlinearity::kink;
                     return config;
                   }(),
                   ControllerSpec::active(), 150, 30});
  // The body's FEM twin, locators A, B and C.
  ExperimentConfig body;
  body.twin_case = TwinCase::body;
  body.locators = "ABC";
  for (const ControllerSpec& spec :
       {ControllerSpec::baseline(), ControllerSpec::nominal(), ControllerSpec::default_controller(),
        w, ControllerSpec::per_component(0.5), ControllerSpec::active()}) {
    add_case(cases, "body_ABC", body, spec);
  }
  return cases;
}

// --- driving a controller -----------------------------------------------------------------------

// What the plant does at one assembly: the assembly, the offset δu*_t and the noise draw.
struct Step {
  AssemblyId assembly;
  VectorX offset;
  double noise = 0.0;
};

// The episode's assemblies, offsets and noise, as run_episode draws them (simulate in
// episode_runner.cpp), for `count` assemblies.
std::vector<Step> plant_steps(const CaseTwin& twin, const ExperimentConfig& config, Index count) {
  const Index d = twin.control_dimension();
  RandomStream run = RandomStream(config.seed).substream("run").substream(std::uint64_t{0});
  RandomStream drift_stream = run.substream("drift");
  BouncingDrift<Dynamic> drift =
      BouncingDrift<Dynamic>::random(d, drift_stream, config.drift_step, config.drift_bound);
  RandomStream noise = run.substream("measurement_noise");
  RandomStream order = run.substream("assembly_order");
  const std::vector<AssemblyId>& assemblies = twin.assemblies();
  std::vector<Step> steps;
  for (Index t = 0; t < count; ++t) {
    drift.advance();
    const std::size_t at = order.uniform_int<std::size_t>(0, assemblies.size() - 1);
    steps.push_back({assemblies[at], drift.offset(), noise.normal()});
  }
  return steps;
}

// What a step shows of the controller, and why it failed if it did (the episode would stop:
// a covariance that cannot be factored; the driver goes on, the state being unchanged).
struct Shown {
  VectorX control;
  VectorX estimate;
  MatrixX covariance;
  double trace = 0.0;
  std::string failure;
};

// Bit for bit (NaN included: a controller that does not estimate reports NaN covariances).
bool same_bits(const Eigen::Ref<const MatrixX>& a, const Eigen::Ref<const MatrixX>& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  const MatrixX x = a;
  const MatrixX y = b;
  return std::memcmp(x.data(), y.data(), sizeof(double) * static_cast<std::size_t>(x.size())) == 0;
}
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

class Driver {
 public:
  Driver(const CaseTwin& twin, const ExperimentConfig& config, Index count)
      : twin_(&twin),
        steps_(plant_steps(twin, config, count)),
        noise_sd_(std::sqrt(config.plant_noise_variance)) {}

  [[nodiscard]] Index dimension() const { return twin_->control_dimension(); }

  // Proposes for step t, into `u`.
  void propose(AnyController& controller, Index t, VectorX& u) const {
    controller.propose(step(t).assembly, u);
  }
  // Observes step t's measured quality at `u`, and what the controller shows after it.
  [[nodiscard]] Shown observe(AnyController& controller, Index t, const VectorX& u) const {
    const Step& s = step(t);
    const VectorX shifted = u - s.offset;
    const double z = twin_->plant_quality(s.assembly, shifted) + noise_sd_ * s.noise;
    try {
      controller.observe(s.assembly, u, z);
    } catch (const std::exception& error) {
      return shown(controller, u, error.what());
    }
    return shown(controller, u);
  }
  // Steps [from, to) of propose and observe.
  [[nodiscard]] std::vector<Shown> run(AnyController& controller, Index from, Index to) const {
    std::vector<Shown> shown_steps;
    VectorX u(dimension());
    for (Index t = from; t < to; ++t) {
      try {
        propose(controller, t, u);
      } catch (const std::exception& error) {
        shown_steps.push_back(shown(controller, u, error.what()));
        continue;
      }
      shown_steps.push_back(observe(controller, t, u));
    }
    return shown_steps;
  }

  [[nodiscard]] Shown shown(const AnyController& controller, const VectorX& u,
                            std::string failure = {}) const {
    Shown out{u, VectorX(dimension()), MatrixX(dimension(), dimension()), 0.0, std::move(failure)};
    controller.offset_estimate(out.estimate);
    controller.offset_covariance(out.covariance);
    out.trace = controller.offset_covariance_trace();
    return out;
  }

 private:
  [[nodiscard]] const Step& step(Index t) const { return steps_.at(static_cast<std::size_t>(t)); }

  const CaseTwin* twin_;
  std::vector<Step> steps_;
  double noise_sd_;
};

void expect_same(const std::vector<Shown>& a, const std::vector<Shown>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t t = 0; t < a.size(); ++t) {
    EXPECT_EQ(a[t].control, b[t].control) << "step " << t;
    EXPECT_TRUE(same_bits(a[t].control, b[t].control)) << "control, step " << t;
    EXPECT_TRUE(same_bits(a[t].estimate, b[t].estimate)) << "estimate, step " << t;
    EXPECT_TRUE(same_bits(a[t].covariance, b[t].covariance)) << "covariance, step " << t;
    EXPECT_TRUE(same_bits(a[t].trace, b[t].trace)) << "trace, step " << t;
    EXPECT_EQ(a[t].failure, b[t].failure) << "step " << t;
  }
}

// The snapshot as `twincal serve` keeps it: text, parsed back.
json through_text(const json& snapshot) { return json::parse(snapshot.dump()); }

// --- the tests ----------------------------------------------------------------------------------

class AnyControllerSnapshot : public ::testing::TestWithParam<SnapshotCase> {
 protected:
  void SetUp() override {
    twin_.emplace(make_case_twin(GetParam().config));
    driver_.emplace(*twin_, GetParam().config, GetParam().before + GetParam().after);
  }
  [[nodiscard]] AnyController make() const {
    return make_episode_controller(*twin_, GetParam().config, GetParam().controller, 0);
  }

  std::optional<CaseTwin> twin_;
  std::optional<Driver> driver_;
};

TEST_P(AnyControllerSnapshot, RestoresBitForBitAfterAnObservation) {
  const Index before = GetParam().before;
  const Index total = before + GetParam().after;
  AnyController original = make();
  (void)driver_->run(original, 0, before);
  const json snapshot = through_text(original.save());

  AnyController restored = make();
  restored.restore(snapshot);
  EXPECT_EQ(restored.save().dump(), snapshot.dump());  // the whole state, back as saved

  expect_same(driver_->run(original, before, total), driver_->run(restored, before, total));
  EXPECT_EQ(original.save().dump(), restored.save().dump());
}

TEST_P(AnyControllerSnapshot, RestoresBitForBitBetweenAProposalAndItsObservation) {
  const Index before = GetParam().before;
  const Index total = before + GetParam().after;
  AnyController original = make();
  (void)driver_->run(original, 0, before);
  VectorX u(driver_->dimension());
  driver_->propose(original, before, u);
  const json snapshot = through_text(original.save());

  AnyController restored = make();
  restored.restore(snapshot);
  EXPECT_EQ(restored.save().dump(), snapshot.dump());
  // The pending proposal is observed by both (a look-ahead commits its preview, the active
  // controller its model's update), then they go on.
  std::vector<Shown> a{driver_->observe(original, before, u)};
  std::vector<Shown> b{driver_->observe(restored, before, u)};
  for (Shown& shown : driver_->run(original, before + 1, total)) a.push_back(std::move(shown));
  for (Shown& shown : driver_->run(restored, before + 1, total)) b.push_back(std::move(shown));
  expect_same(a, b);
  EXPECT_EQ(original.save().dump(), restored.save().dump());
}

TEST_P(AnyControllerSnapshot, RestoresIntoAFreshControllerAndIntoAUsedOne) {
  // A snapshot of a fresh controller restores a used one to its start.
  const Index before = GetParam().before;
  AnyController fresh = make();
  const json start = through_text(fresh.save());
  AnyController used = make();
  (void)driver_->run(used, 0, before);
  used.restore(start);
  expect_same(driver_->run(fresh, 0, before), driver_->run(used, 0, before));
}

// The JSON pointers of every member of every object in `value` (not the array entries; of an
// array's objects, those of the first and the last: a history's entries are alike).
void member_pointers(const json& value, const json::json_pointer& at,
                     std::vector<json::json_pointer>& out) {
  if (value.is_object()) {
    for (const auto& [key, member] : value.items()) {
      out.push_back(at / key);
      member_pointers(member, at / key, out);
    }
  } else if (value.is_array() && !value.empty()) {
    member_pointers(value.front(), at / 0, out);
    if (value.size() > 1) member_pointers(value.back(), at / (value.size() - 1), out);
  }
}

// The field name an error names for a pointer: "/estimator/history/3/quality" →
// "estimator.history[3].quality".
std::string field_name(const json& snapshot, const json::json_pointer& pointer) {
  std::string name;
  json::json_pointer at;
  for (const std::string& token : [&] {
         std::vector<std::string> tokens;
         json::json_pointer p = pointer;
         while (!p.empty()) {
           tokens.insert(tokens.begin(), p.back());
           p.pop_back();
         }
         return tokens;
       }()) {
    if (snapshot.at(at).is_array()) {
      name += "[" + token + "]";
    } else {
      name += name.empty() ? token : "." + token;
    }
    at /= token;
  }
  return name;
}

// Restores `bad`, which must be refused with an error of type E naming `field`, and leave the
// controller's state as it was.
template <typename E>
void expect_refused(AnyController& controller, const json& bad, const std::string& field) {
  const std::string before = controller.save().dump();
  try {
    controller.restore(bad);
    ADD_FAILURE() << "restored a snapshot without a valid " << field;
  } catch (const E& error) {
    EXPECT_EQ(error.argument(), field) << error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "expected a typed error naming " << field << ", got: " << error.what();
  }
  EXPECT_EQ(controller.save().dump(), before) << "after the refused " << field;
}

TEST_P(AnyControllerSnapshot, RefusesABadSnapshotAndGoesOnAsBefore) {
  const Index before = GetParam().before;
  const Index total = before + GetParam().after;
  const Index d = driver_->dimension();
  AnyController tried = make();
  AnyController untouched = make();
  expect_same(driver_->run(tried, 0, before), driver_->run(untouched, 0, before));
  AnyController other = make();  // a snapshot to refuse that is not the tried one's state
  (void)driver_->run(other, 0, before / 2);
  const json good = through_text(other.save());

  json bad = good;
  bad["format"] = "twincal.another_controller";
  expect_refused<InvalidArgumentError>(tried, bad, "format");
  bad = good;
  bad["dimension"] = d + 1;
  expect_refused<DimensionMismatchError>(tried, bad, "dimension");
  bad = good;
  bad["dimension"] = "three";
  expect_refused<InvalidArgumentError>(tried, bad, "dimension");
  // Every field of every part is needed, and a missing one is named where it was.
  std::vector<json::json_pointer> members;
  member_pointers(good, json::json_pointer{}, members);
  for (const json::json_pointer& member : members) {
    bad = good;
    bad.at(member.parent_pointer()).erase(member.back());
    expect_refused<InvalidArgumentError>(tried, bad, field_name(good, member));
  }
  // A non-finite estimate.
  for (const char* estimate :
       {"/filter/state/0", "/mean/0", "/components/0/filter/state/0", "/last_quality"}) {
    const json::json_pointer pointer(estimate);
    if (!good.contains(pointer)) continue;
    bad = good;
    bad[pointer] = "inf";
    expect_refused<Error>(tried, bad, field_name(good, pointer));
  }

  expect_same(driver_->run(tried, before, total), driver_->run(untouched, before, total));
}

INSTANTIATE_TEST_SUITE_P(EveryController, AnyControllerSnapshot,
                         ::testing::ValuesIn(snapshot_cases()),
                         [](const ::testing::TestParamInfo<SnapshotCase>& info) {
                           return info.param.name;
                         });

// The labels the experiments know are all here.
TEST(AnyControllerSnapshotCases, CoverEveryControllerSchemeSamplerAndLoss) {
  std::vector<std::string> labels;
  bool filters[5] = {};
  bool samplers[4] = {};
  bool losses[4] = {};
  for (const SnapshotCase& c : snapshot_cases()) {
    labels.push_back(c.controller.label());
    if (c.controller.estimates()) filters[static_cast<int>(c.config.filter)] = true;
    if (c.controller.uses_w()) {
      samplers[static_cast<int>(c.config.sampler)] = true;
      losses[static_cast<int>(c.config.exploration)] = true;
    }
  }
  for (const std::string label :
       {"baseline", "nominal", "default", "w=0", "w=0.5", "w=1", "per-component:w=0.5", "active"}) {
    EXPECT_NE(std::find(labels.begin(), labels.end(), label), labels.end()) << label;
  }
  for (const bool covered : filters) EXPECT_TRUE(covered);
  for (const bool covered : samplers) EXPECT_TRUE(covered);
  for (const bool covered : losses) EXPECT_TRUE(covered);
}

}  // namespace
}  // namespace twincal
