// Your own black box: DeviationNonlinearity policies written here, outside the library, as a
// user would write the shape of their own twin (models/deviation_nonlinearity.hpp), and the active
// controller run on them with its default settings. Two sets:
//   first  soft stops, a dead band, cubic stiffening of every key point, waviness, saturation,
//          one-sided stiffening: kept out of the project while the controller was designed (the
//          last two were written after the controller of commit ce44677);
//   later  neighbouring key points that couple, one-sided gaps (hinges), exponential stiffening
//          in the locators, snap-through (Q jumps): written on 2026-11-29 after the controller of
//          commit 3b80229 and first run on it.
// docs/reproduction.md ("Black-box twins") reports what this program prints.
//
// Two modes, the paper's protocol (100 assemblies, the bouncing drift of eq. (15) on every
// locator, NLopt-searched u0 and z*):
//   twin   the twin is the key-point twin with the shape (the plant is the twin plus δu*);
//   plant  the twin is the key-point twin without it and the plant has it (Assumption 1 broken).
// Prints per shape: the twin's departure from a quadratic (twin mode), the median over the runs
// of the mean relative residual (z − z*)/z* without calibration and with the active controller,
// the runs whose estimate lost the offset (further from δu* than no estimate, second half), and
// the mean over the runs of the paired difference active − no calibration against the spread
// (standard deviation over the runs) of no calibration; "beyond" marks a difference above it.
//
//   custom_nonlinearity [twin|plant] [runs] [dimension] [seed] [twin seed] [correction step]
//                       [surprise step] [strength] [first|later|all] [deviations|quality]
//
// The correction and surprise steps are ActiveOptions::correction_step_fraction (0, the default:
// unbounded) and surprise_step_fraction (its default, ¼, unless given); the strength s scales
// every shape (1 unless given); the set is `first` unless given; `quality` fits the controller's
// models from Q² alone, as for a black box that answers only Q (QuadraticSurrogateOptions::
// from_deviations off), where the default fits them from the key points' deviations.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "black_box_episode.hpp"
#include "twincal/controllers/presets.hpp"
#include "twincal/controllers/searched_optimum_twin.hpp"
#include "twincal/models/deviation_nonlinearity.hpp"
#include "twincal/models/key_point_twin.hpp"
#include "twincal/models/no_nonlinearity.hpp"
#include "twincal/models/quadratic_departure.hpp"

namespace {

using namespace twincal;
using examples::median;
using Deviations = Eigen::Ref<VectorX>;
using Constant = Eigen::Ref<const VectorX>;

// Beyond a limit (per key point, drawn) a point moves only 20 % as far: a soft stop.
class SoftStop {
 public:
  SoftStop(Index key_points, Index dimension, double strength, const RandomStream& stream)
      : limit_(key_points), strength_(strength) {
    RandomStream draws = stream.substream("soft_stop");
    for (Index i = 0; i < key_points; ++i) {
      limit_(i) = 0.3 * std::sqrt(static_cast<double>(dimension)) * (0.2 + draws.uniform());
    }
  }
  static constexpr std::string_view name() { return "soft stop"; }
  void apply(const Constant&, const Constant&, const Constant& moved, Deviations r) const {
    for (Index i = 0; i < r.size(); ++i) {
      const double beyond = std::abs(moved(i)) - limit_(i);
      if (beyond > 0.0) r(i) -= strength_ * 0.8 * std::copysign(beyond, moved(i));
    }
  }

 private:
  VectorX limit_;
  double strength_;
};

// Small moves are taken up by play (per key point, drawn): a dead band.
class DeadBand {
 public:
  DeadBand(Index key_points, Index dimension, double strength, const RandomStream& stream)
      : band_(key_points), strength_(strength) {
    RandomStream draws = stream.substream("dead_band");
    for (Index i = 0; i < key_points; ++i) {
      band_(i) = 0.3 * std::sqrt(static_cast<double>(dimension)) * draws.uniform();
    }
  }
  static constexpr std::string_view name() { return "dead band"; }
  void apply(const Constant&, const Constant&, const Constant& moved, Deviations r) const {
    for (Index i = 0; i < r.size(); ++i) {
      r(i) -= strength_ * 0.7 * std::clamp(moved(i), -band_(i), band_(i));
    }
  }

 private:
  VectorX band_;
  double strength_;
};

// Every key point stiffens (or softens) with the cube of how far it moved.
class Cubic {
 public:
  Cubic(Index /*key_points*/, Index dimension, double strength, const RandomStream& /*stream*/)
      : scale_(0.4 * std::sqrt(static_cast<double>(dimension))), strength_(strength) {}
  static constexpr std::string_view name() { return "cubic"; }
  void apply(const Constant&, const Constant&, const Constant& moved, Deviations r) const {
    for (Index i = 0; i < r.size(); ++i) {
      const double m = moved(i) / scale_;
      r(i) += strength_ * 0.3 * scale_ * m * m * m;
    }
  }

 private:
  double scale_;
  double strength_;
};

// A ripple in every key point's response (phases drawn): smooth, but no polynomial.
class Waviness {
 public:
  Waviness(Index key_points, Index dimension, double strength, const RandomStream& stream)
      : phase_(key_points),
        scale_(0.2 * std::sqrt(static_cast<double>(dimension))),
        strength_(strength) {
    RandomStream draws = stream.substream("waviness");
    for (Index i = 0; i < key_points; ++i) phase_(i) = 2.0 * M_PI * draws.uniform();
  }
  static constexpr std::string_view name() { return "waviness"; }
  void apply(const Constant&, const Constant&, const Constant& moved, Deviations r) const {
    for (Index i = 0; i < r.size(); ++i) {
      r(i) += strength_ * 0.3 * scale_ *
              (std::sin(3.0 * moved(i) / scale_ + phase_(i)) - std::sin(phase_(i)));
    }
  }

 private:
  VectorX phase_;
  double scale_;
  double strength_;
};

// Every key point saturates: a part that bottoms out smoothly. (This shape and the next were
// written after the controller of commit ce44677 and first run on it.)
class Saturation {
 public:
  Saturation(Index /*key_points*/, Index dimension, double strength, const RandomStream&)
      : limit_(0.5 * std::sqrt(static_cast<double>(dimension))), strength_(strength) {}
  static constexpr std::string_view name() { return "saturation"; }
  void apply(const Constant&, const Constant&, const Constant& moved, Deviations r) const {
    for (Index i = 0; i < r.size(); ++i) {
      r(i) -= strength_ * 0.6 * (moved(i) - limit_ * std::tanh(moved(i) / limit_));
    }
  }

 private:
  double limit_;
  double strength_;
};

// One-sided stiffening (the side drawn per key point): smooth, but not symmetric in the move.
class OneSided {
 public:
  OneSided(Index key_points, Index dimension, double strength, const RandomStream& stream)
      : side_(key_points),
        scale_(0.4 * std::sqrt(static_cast<double>(dimension))),
        strength_(strength) {
    RandomStream draws = stream.substream("one_sided");
    for (Index i = 0; i < key_points; ++i) side_(i) = draws.uniform() < 0.5 ? -1.0 : 1.0;
  }
  static constexpr std::string_view name() { return "one-sided"; }
  void apply(const Constant&, const Constant&, const Constant& moved, Deviations r) const {
    for (Index i = 0; i < r.size(); ++i) {
      const double m = std::max(0.0, side_(i) * moved(i)) / scale_;
      r(i) += side_(i) * strength_ * 0.5 * scale_ * m * m;
    }
  }

 private:
  VectorX side_;
  double scale_;
  double strength_;
};

// Neighbouring key points couple (the stiffness of the sheet between them): each moves further by
// a product of its own move and the next one's. (This shape and the three after it were written
// on 2026-11-29, after the controller of commit 3b80229.)
class Coupled {
 public:
  Coupled(Index /*key_points*/, Index dimension, double strength, const RandomStream& /*stream*/)
      : scale_(0.4 * std::sqrt(static_cast<double>(dimension))), strength_(strength) {}
  static constexpr std::string_view name() { return "coupled"; }
  void apply(const Constant&, const Constant&, const Constant& moved, Deviations r) const {
    const Index m = r.size();
    for (Index i = 0; i < m; ++i) {
      r(i) += strength_ * 0.3 * scale_ * (moved(i) / scale_) * (moved((i + 1) % m) / scale_);
    }
  }

 private:
  double scale_;
  double strength_;
};

// A gap on one side of each key point (side and width drawn): once it closes, the point is held
// back 80 %, and on the other side it moves freely — a hinge rather than a symmetric stop.
class Hinge {
 public:
  Hinge(Index key_points, Index dimension, double strength, const RandomStream& stream)
      : gap_(key_points), side_(key_points), strength_(strength) {
    RandomStream draws = stream.substream("hinge");
    for (Index i = 0; i < key_points; ++i) {
      gap_(i) = 0.25 * std::sqrt(static_cast<double>(dimension)) * draws.uniform();
      side_(i) = draws.uniform() < 0.5 ? -1.0 : 1.0;
    }
  }
  static constexpr std::string_view name() { return "hinge"; }
  void apply(const Constant&, const Constant&, const Constant& moved, Deviations r) const {
    for (Index i = 0; i < r.size(); ++i) {
      const double beyond = side_(i) * moved(i) - gap_(i);
      if (beyond > 0.0) r(i) -= strength_ * 0.8 * side_(i) * beyond;
    }
  }

 private:
  VectorX gap_;
  VectorX side_;
  double strength_;
};

// The locators themselves stiffen exponentially on one side (their error e from the affine
// optimum, not the key points' moves), mixed into the key points by drawn weights.
class Exponential {
 public:
  Exponential(Index key_points, Index dimension, double strength, const RandomStream& stream)
      : weights_(key_points, dimension), strength_(strength) {
    RandomStream draws = stream.substream("exponential");
    const double norm = 1.0 / std::sqrt(static_cast<double>(dimension));
    for (Index i = 0; i < key_points; ++i) {
      for (Index j = 0; j < dimension; ++j) weights_(i, j) = norm * (2.0 * draws.uniform() - 1.0);
    }
  }
  static constexpr std::string_view name() { return "exponential"; }
  void apply(const Constant&, const Constant& error, const Constant&, Deviations r) const {
    for (Index j = 0; j < error.size(); ++j) {
      const double e = error(j) / scale_;
      r += (strength_ * 0.3 * scale_ * (std::exp(e) - 1.0 - e)) * weights_.col(j);
    }
  }

 private:
  static constexpr double scale_ = 0.25;  // mm: a quarter of the default box's half-width
  MatrixX weights_;
  double strength_;
};

// Snap-through: beyond a threshold (per key point, drawn) a key point jumps by a fixed amount, so
// Q itself is discontinuous — no local model holds across the jump.
class Snap {
 public:
  Snap(Index key_points, Index dimension, double strength, const RandomStream& stream)
      : threshold_(key_points),
        jump_(0.1 * std::sqrt(static_cast<double>(dimension))),
        strength_(strength) {
    RandomStream draws = stream.substream("snap");
    for (Index i = 0; i < key_points; ++i) {
      threshold_(i) = 0.4 * std::sqrt(static_cast<double>(dimension)) * (0.2 + draws.uniform());
    }
  }
  static constexpr std::string_view name() { return "snap"; }
  void apply(const Constant&, const Constant&, const Constant& moved, Deviations r) const {
    for (Index i = 0; i < r.size(); ++i) {
      if (std::abs(moved(i)) > threshold_(i)) {
        r(i) += strength_ * jump_ * std::copysign(1.0, moved(i));
      }
    }
  }

 private:
  VectorX threshold_;
  double jump_;
  double strength_;
};

static_assert(DeviationNonlinearity<SoftStop> && DeviationNonlinearity<DeadBand> &&
              DeviationNonlinearity<Cubic> && DeviationNonlinearity<Waviness> &&
              DeviationNonlinearity<Saturation> && DeviationNonlinearity<OneSided> &&
              DeviationNonlinearity<Coupled> && DeviationNonlinearity<Hinge> &&
              DeviationNonlinearity<Exponential> && DeviationNonlinearity<Snap>);

struct Settings {
  bool plant_mode = false;
  int runs = 10;
  Index dimension = 3;
  std::uint64_t seed = 7;
  std::uint64_t twin_seed = 11;
  ActiveOptions active{};  // the defaults; correction_step_fraction from the command line
  double strength = 1.0;   // s of every shape
  std::string set = "first";
};

struct Outcome {
  double baseline = 0.0;  // mean (z − z*)/z* at u0 − δu*
  double active = 0.0;
  bool lost = false;
};

// One episode: `twin` drives the controller, `plant` answers (the same object in twin mode).
template <typename T, typename P>
Outcome run_episode(const T& twin, const P& plant, const RandomStream& run,
                    const ActiveOptions& options) {
  ActiveController<T> controller(twin, run.substream("controller"), options);
  Outcome outcome;
  outcome.lost = examples::drifting_episode(
      twin, run,
      [&](const AssemblyId& x, const VectorX& offset) {
        const VectorX u = controller.propose(x);
        const double z = plant.quality(x, VectorX(u - offset));
        controller.observe(x, u, z);
        const double best = plant.optimal_quality(x);
        outcome.active += (z - best) / best;
        outcome.baseline += (plant.quality(x, VectorX(twin.optimum(x) - offset)) - best) / best;
      },
      [&] { return VectorX(controller.offset_estimate()); });
  const auto assemblies = static_cast<double>(twin.assemblies().size());
  outcome.baseline /= assemblies;
  outcome.active /= assemblies;
  return outcome;
}

template <typename Shape>
void report(const Settings& settings) {
  KeyPointTwinOptions options;
  options.assemblies.dimension = settings.dimension;
  options.strength = settings.strength;
  const RandomStream twin_stream(settings.twin_seed);
  KeyPointTwin<Shape> shaped(options, twin_stream);
  const std::vector<AssemblyId> assemblies = shaped.assemblies();
  const SearchedOptimumTwin<KeyPointTwin<Shape>> with_shape(std::move(shaped), assemblies);
  // The twin's own departure from a quadratic, median over 5 assemblies.
  std::vector<double> departures;
  for (std::size_t k = 0; k < 5; ++k) {
    departures.push_back(quadratic_departure(with_shape, assemblies[k],
                                             with_shape.optimum(assemblies[k]), RandomStream(5)));
  }
  const KeyPointTwin<NoNonlinearity> without_shape(options, twin_stream);
  std::vector<double> baseline;
  std::vector<double> active;
  int lost = 0;
  for (int r = 0; r < settings.runs; ++r) {
    const RandomStream run =
        RandomStream(settings.seed).substream("run").substream(static_cast<std::uint64_t>(r));
    const Outcome outcome = settings.plant_mode
                                ? run_episode(without_shape, with_shape, run, settings.active)
                                : run_episode(with_shape, with_shape, run, settings.active);
    baseline.push_back(outcome.baseline);
    active.push_back(outcome.active);
    lost += outcome.lost ? 1 : 0;
  }
  const double ratio = median(active) / median(baseline);
  // The plant ≠ twin target's yardstick: the paired mean difference against the baseline's
  // run-to-run standard deviation (docs/reproduction.md, "Twin ≠ plant").
  double difference = 0.0;
  double mean = 0.0;
  for (std::size_t r = 0; r < baseline.size(); ++r) {
    difference += active[r] - baseline[r];
    mean += baseline[r];
  }
  const auto runs = static_cast<double>(baseline.size());
  difference /= runs;
  mean /= runs;
  double spread = 0.0;
  for (const double b : baseline) spread += (b - mean) * (b - mean);
  spread = runs > 1.0 ? std::sqrt(spread / (runs - 1.0)) : 0.0;
  fmt::print("{:<10} {:>9.3f} {:>14.4f} {:>10.4f} ({:.2f}x) {:>4}/{} {:>+11.4f} {:>7.4f}{}\n",
             Shape::name(), median(departures), median(baseline), median(active), ratio, lost,
             settings.runs, difference, spread, difference > spread ? "  beyond" : "");
}

}  // namespace

int main(int argc, char** argv) {
  Settings settings;
  const std::string mode = argc > 1 ? argv[1] : "twin";
  settings.plant_mode = mode == "plant";
  if (argc > 2) settings.runs = std::atoi(argv[2]);
  if (argc > 3) settings.dimension = std::atol(argv[3]);
  if (argc > 4) settings.seed = std::strtoull(argv[4], nullptr, 10);
  if (argc > 5) settings.twin_seed = std::strtoull(argv[5], nullptr, 10);
  if (argc > 6) settings.active.correction_step_fraction = std::strtod(argv[6], nullptr);
  if (argc > 7) settings.active.surprise_step_fraction = std::strtod(argv[7], nullptr);
  if (argc > 8) settings.strength = std::strtod(argv[8], nullptr);
  if (argc > 9) settings.set = argv[9];
  const std::string models = argc > 10 ? argv[10] : "deviations";
  settings.active.surrogate.from_deviations = models == "deviations";
  if (const std::optional<std::string> problem = settings.active.validate()) {
    fmt::print(stderr, "custom_nonlinearity: ActiveOptions: {}\n", *problem);
    return 2;
  }
  // Which value broke which rule, then the usage line.
  bool refused = false;
  const auto require = [&](bool holds, const std::string& problem) {
    if (holds) return;
    fmt::print(stderr, "custom_nonlinearity: {}\n", problem);
    refused = true;
  };
  require(settings.strength >= 0.0 && settings.strength <= 10.0,
          fmt::format("strength: value is {}; rule: in [0, 10]", settings.strength));
  require(settings.set == "first" || settings.set == "later" || settings.set == "all",
          fmt::format("set: value is '{}'; rule: first, later or all", settings.set));
  require(models == "deviations" || models == "quality",
          fmt::format("models: value is '{}'; rule: deviations or quality", models));
  if (refused || (mode != "twin" && mode != "plant") || settings.runs < 1 ||
      settings.dimension < 1) {
    fmt::print(stderr,
               "usage: custom_nonlinearity [twin|plant] [runs >= 1] [dimension >= 1] [seed] "
               "[twin seed] [correction step fraction] [surprise step fraction] "
               "[strength in [0, 10]] [first|later|all] [deviations|quality]\n");
    return 2;
  }
  const bool first = settings.set == "first" || settings.set == "all";
  const bool later = settings.set == "later" || settings.set == "all";
  fmt::print(
      "{} mode, d = {}, {} runs of 100 assemblies, seed {}, twin seed {}, correction step {}, "
      "surprise step {}, strength {}, shapes {}, models from {}\n",
      mode, settings.dimension, settings.runs, settings.seed, settings.twin_seed,
      settings.active.correction_step_fraction, settings.active.surprise_step_fraction,
      settings.strength, settings.set, models);
  fmt::print("{:<10} {:>9} {:>14} {:>17} {:>6} {:>11} {:>7}\n", "shape", "departure",
             "no calibration", "active", "lost", "difference", "spread");
  if (first) {
    report<SoftStop>(settings);
    report<DeadBand>(settings);
    report<Cubic>(settings);
    report<Waviness>(settings);
    report<Saturation>(settings);
    report<OneSided>(settings);
  }
  if (later) {
    report<Coupled>(settings);
    report<Hinge>(settings);
    report<Exponential>(settings);
    report<Snap>(settings);
  }
  return 0;
}
