#pragma once
/// @file
/// `ConstantVelocityOptions`: the settings of the moving-horizon estimator of a drifting offset
/// (constant_velocity_estimator.hpp). Scales are fractions of the twin's box width, so one set
/// serves every twin.

#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "twincal/core/eigen.hpp"
#include "twincal/core/options.hpp"

namespace twincal {

struct ConstantVelocityOptions {
  /// Prior standard deviation of the offset when an episode starts, per locator, / box width:
  /// the twin was calibrated then (the paper's δu*_0 = 0, eq. 15), so the plant starts near it.
  /// 0.15 rather than position_fraction: with fewer assemblies than the 2d unknowns (a drift at
  /// d = 32 turns back after about 40) a wide start lets the fit wander along directions the
  /// probes have not resolved (measured over 8 seed pairs: analytic d = 32 0.16–0.32 → 0.12–0.19,
  /// body/all 0.27–0.45 → 0.25–0.40; 0.1–0.3 all do about as well; docs/reproduction.md).
  double initial_position_fraction = 0.15;
  /// The largest prior standard deviation of the offset the estimator admits later, per locator,
  /// / box width (the velocity's uncertainty widens the offset's up to it; see cap_prior()).
  double position_fraction = 0.5;
  /// Optionally, the largest offset the estimate takes, per locator, / box width: beyond it the
  /// fit meets a wall (a penalty of one σz per 1e-4 of the box width beyond it, so the estimate
  /// stays within it to about a hundredth of the box whatever the data say). Where the twin
  /// cannot explain the plant, an offset the quality hardly sees can explain it, and the
  /// estimate runs off: the door behind its contact plant ran 10 mm from δu* in a ±1 mm box (the
  /// paper's divergence) in 9 and 3 of 10 runs. At 1 (a whole box width) none does, though every
  /// run stays lost; but a user's plant that stiffens cubically ran further above the baseline
  /// (cells beyond its spread 5 → 7 of 84); where the plant is the twin no estimate reached 1
  /// (docs/reproduction.md, "A wall for the estimate"). Infinity (the default): no wall.
  double max_position_fraction = std::numeric_limits<double>::infinity();
  /// Prior standard deviation of the offset's velocity (per assembly), per locator, / box width.
  double velocity_fraction = 0.05;
  /// A change of velocity is declared when the root-mean-square normalized residual of the last
  /// `change_window` assemblies under the fit exceeds `change_gate` (the same gate sends a fit
  /// that explains its history badly to the mirror and prior-mean starts). 2 rather than 3:
  /// a false alarm costs little, as the restart prior keeps the old fit's information except
  /// along the velocity's line, while a late detection biases every assembly until it comes
  /// (measured over 4 seed pairs: body/all 0.50–0.57 → 0.37–0.45, analytic d = 3 and 6 about
  /// halved, no group worse by more than noise; docs/reproduction.md).
  double change_gate = 2.0;
  Index change_window = 2;
  /// The change test after a refit (ConstantVelocityEstimator::test_change()) also reads the
  /// innovations, each z against the prediction made before it joined the fit: a change is
  /// declared when each of the last `innovation_window` normalized innovations ν²/S exceeds 1
  /// and their mean exceeds change_gate² in their own unit (at least 1: where recent models err
  /// the misfit scale, uncapped by max_misfit_scale, and no test until that scale is known;
  /// elsewhere gate_unit()), once at
  /// least max(innovation_window, 2d) innovations have joined since the fit last restarted. The
  /// fit's own residuals, which the gate reads, miss a turn of the drift that its 2d unknowns can
  /// bend to: traced on a twin with closing gaps at d = 12, innovations at 5–40 times their
  /// variance for 10–25 assemblies after a turn while the gate read below 1, and the estimate
  /// ran 0.7 mm from an offset of 0.3. Fewer than 2d since a restart, and restarts follow one
  /// another where models err, each cutting the history the estimate rests on (lost runs of the
  /// analytic family answering only Q, 4 → 9 of 480). 0: off. Measured 2026-12-01
  /// (docs/reproduction.md, "A change seen in the innovations").
  Index innovation_window = 3;
  /// The gate and the significance test are in units of the history's own misfit s²: the
  /// median normalized innovation ν²/S of the last `misfit_window` assemblies whose model errs
  /// (τ² > 0) over χ²(1)'s median (0.4549), when that exceeds 1 (0: in units of σz alone; a twin
  /// whose models pass their checks always is). A twin whose local models err more
  /// than their τ² says (contact, soft stops) would otherwise restart the fit at nearly every
  /// assembly — measured: 64–76 restarts per 100 assemblies on contact twins at d = 6 and 12,
  /// about 1 with the scale; 2 on quadratic twins either way (docs/reproduction.md).
  Index misfit_window = 25;
  /// The change gate's unit is s², at most `max_misfit_scale`. The scale climbs with the
  /// residuals it measures, so an estimate that misses a turn of the drift raises its own gate:
  /// traced in lost runs, s² reached 57–460 and kept the gate shut for 57–73 assemblies. Beyond
  /// the bound the misfit is taken to be the estimate's, not its models'. 10 rather than
  /// unbounded: runs that lost the offset, over the analytic family's 96 development and
  /// held-out cells 23 → 18 and over the user's shapes on five seed pairs 38 → 14, the residual
  /// unchanged; 3 and 5 restart the fit too often on contact, 30 and 100 leave the soft stops
  /// lost (docs/reproduction.md, "A bound on the misfit's unit"). Infinity: unbounded.
  double max_misfit_scale = 10.0;
  /// With min_gate_unit < 1, where none of the last misfit_window entries' models erred, the
  /// gate's unit is the plant's own: the median of their squared innovations ν²/(σz² + τ²)
  /// (each predicted before its entry joined the fit) over χ²(1)'s median, within
  /// [min_gate_unit, 1]. A plant measured more precisely than σz says (the paper's is
  /// noise-free, σz² its filters' setting) turns its drift in residuals far below σz, which a
  /// gate in units of σz² misses for tens of assemblies; a plant as noisy as σz says, or an
  /// estimate that predicts it worse than σz (d = 32), keeps the unit at 1. 1 (off: the unit
  /// is σz², or the models' misfit scale, as without the option) by default: at 0.01, over ten seed
  /// pairs, the FEM body/ABC twin's residual falls from 0.12–0.23 to 0.08–0.15, the analytic
  /// quadratic twin's at d = 3 by a quarter to a half and the door's lost runs from 9–10 to 3–7 of
  /// 10, but body/all runs up to 0.04 higher and the door misses its residual target on a held-out
  /// pair (docs/reproduction.md, "The change gate in the plant's own units").
  double min_gate_unit = 1.0;
  /// With min_erring_gate_unit < 1, a change test on a fit whose models its owner has refitted
  /// where the fit uses them (ConstantVelocityEstimator::test_change(); the active controller's
  /// ActiveOptions::change_test_after_refit), where some of the last misfit_window entries'
  /// models erred, takes the gate's unit from the plant as min_gate_unit does: the median
  /// innovation ν²/(σz² + τ²) over χ²(1)'s median, within [min_erring_gate_unit, 1]. Those
  /// residuals are the twin's own, not its models' errors away from their checks, so the misfit
  /// scale (at least 1) that kept the gate from restarting the fit at stale models' misfits is not
  /// needed there, and a turn of the drift shows far below σz as it does on exact models. 0.01
  /// by default: with the test after refit, on the analytic family's 60 development cells the sum
  /// of the residual ratios to the baseline went 8.87 → 8.05 and lost runs 7 → 9 (13 with
  /// neither), on 36 held-out cells 5.06 → 4.43 and 1 → 1 (docs/reproduction.md, "The change
  /// test after the refit"). A fit whose gate is consulted as it is fitted (ChangeTest::now)
  /// keeps the misfit scale: there, without the test after refit, the plant's unit took contact
  /// at d = 19 from 0.16–0.29 to 0.34–0.45 times the baseline. 1: the misfit scale everywhere.
  double min_erring_gate_unit = 0.01;
  /// Where one of the last misfit_window entries' models erred, the fit weighs each assembly by
  /// 1/(s·σz² + τ²) instead of 1/(σz² + τ²), s the plant's own unit: the median innovation
  /// ν²/(σz² + τ²) of the last misfit_window assemblies (each z against the prediction made
  /// before it joined the fit) over χ²(1)'s median, within [min_erring_fit_unit, 1] (1 until half
  /// that window is in; ConstantVelocityEstimator::fit_unit()). σz² is the filters' setting, not
  /// the plant's noise (the paper's plant has none). Where the quality near the optimum moves
  /// with the offset by less than σz — a user's gap twin with z* ≈ 0.15 mm against the paper's
  /// σz = 0.01 mm, its first normalized innovations at 10⁻⁴–10⁻¹ — a fit in units of σz² takes its
  /// 2d unknowns (24 at d = 12) from residuals it cannot tell from noise: traced (seed 77, run 1,
  /// from the deviations), the estimate ran 0.2–1.1 mm from the offset from its fifth assembly on
  /// while its normalized residuals stayed mostly below 1, and the run was lost. A plant as noisy
  /// as σz says keeps s near 1. Measured on 2026-12-03 at 0.01 (the floor of min_erring_gate_unit),
  /// 0.1 and 1 (off), in that order: the user's gap and clamp twins at d = 12 (five twin seeds
  /// each, both ways) lose 0, 5 and 20 of 200 runs, every cell at most 0.27× the baseline at 0.01
  /// (0.70× off); the user's key-point shapes (d = 3 and 12, nine seed pairs) lose 9, 6 and 3 of
  /// 1800, their residual at d = 3 up to a fifth higher at 0.01 than off; the door, whose quality
  /// hardly sees the offset, loses more runs behind contact (75 of 90 at 0.01, 47 off) at a lower
  /// residual (docs/reproduction.md, "The fit in the plant's own units"). Models that pass their
  /// checks keep 1/(σz² + τ²): the quadratic twins are unchanged.
  /// The plant's unit holds while the fit predicts the plant: for the change_lag assemblies from
  /// one whose innovation ν²/(σz² + τ²) exceeds change_gate² · max_misfit_scale (40, beyond what
  /// the gate accepts in its widest unit), s is 1. Traced on the user's cubic key-point twin at
  /// d = 3 (seed pair 199/211, run 4): at a turn of the drift, with s at 0.04–0.09 and models
  /// that claimed τ² of 10⁻⁷–10⁻¹⁴ where the fit used them, the restarted fit bent its six unknowns
  /// through the few assemblies since the restart, innovations of 10²–10⁴ followed, and the run was
  /// lost. Measured on 2026-12-03 against s at every fit: the user's shapes lose 5 instead of 9 of
  /// 1800 runs on the pairs that chose 0.01 and 5 instead of 7 of 800 on four pairs never run
  /// before, the analytic family runs 7 % and 12 % lower at d = 3 and 6, and the gap and clamp
  /// twins at d = 12 lose 1 of 200; s = 1 after any innovation beyond change_gate² lost 17 of those
  /// 200, and s = 1 until 2d innovations have joined since a restart 23 (docs/reproduction.md, "The
  /// plant's unit holds while the fit predicts the plant"). 1: off.
  double min_erring_fit_unit = 0.01;
  /// At a change the fit restarts from its estimate of `change_lag` assemblies ago (before the
  /// change could bias it), keeping only the assemblies measured since then.
  Index change_lag = 6;
  /// At a change the restart prior widens the offset by change_position_spread · b bᵀ and gives
  /// the velocity change_velocity_spread · b bᵀ + (change_velocity_floor_fraction · width)² I, b
  /// the velocity then estimated: a drift tends to keep its line and may turn back on it.
  double change_position_spread = 9.0;
  double change_velocity_spread = 4.0;
  /// The floor is how far the velocity may leave the old line. The line is the fit's, which at
  /// d = 19 rests on fewer assemblies than its 2d unknowns: at 5e-4 (the default until 2026-11-29)
  /// the restarts held the estimate on a wrong line, traced in lost runs moving at half the
  /// offset's speed along the drift's line and as far across it. 2e-3 rather than 5e-4: on the
  /// analytic family's 60 development cells lost runs 9 → 0, the sum of the residual ratios to
  /// the baseline 8.05 → 8.16; on 60 held-out cells 4 → 0 lost, 7.69 → 8.06; on the user's shapes
  /// (never used in the choice) 7 → 0 lost, 7.95 → 7.90. 5e-3: 1 lost, 8.86 on the development
  /// cells (docs/reproduction.md, "The restart's velocity across the old line").
  double change_velocity_floor_fraction = 2e-3;
  /// At a change the restart prior also widens each locator's offset by
  /// (change_position_floor_fraction · width)². The old fit's covariance can be far tighter than
  /// what the assemblies since the change say: traced on a cubic black box at d = 3, a restart
  /// landed 0.6–1.0 mm from the offset with standard deviations of 0.003–0.04 mm, the
  /// innovations ran at 10²–10⁵ times their variance for the rest of the run, and the estimate
  /// never came back. 0.05 rather than 0 (chosen on the user's ten shapes at d = 3, answering
  /// only Q, ten development pairs: 11.05 (7 lost) → 10.77 (2); 0.02 10.94 (3), 0.1 10.96 (3),
  /// 0.15 11.02 (3)); after the choice, on pairs never used to choose, d = 3 3.18 (3) → 3.20
  /// (0), d = 12 4.54 (4) → 4.32 (0); the analytic family answering only Q, 96 cells, 14.88 (5)
  /// → 14.50 (4); every quadratic twin's target still met, each group a little better
  /// (docs/reproduction.md, "The restart's spread"). 0: off.
  double change_position_floor_fraction = 0.05;
  /// The offset is significant when its fit beats δu = 0 by more than the χ²(2d) mean plus
  /// `significance` standard deviations of the normalized data cost (a twin whose quality hardly
  /// depends on the offset, e.g. the door, never gets there, and is then not corrected).
  double significance = 3.0;
  /// The longest history kept (assemblies); older ones are dropped.
  Index max_history = 128;
  /// Gauss–Newton iterations per fit, and the relative step at which they stop.
  int max_iterations = 20;
  double step_tolerance = 1e-10;

  [[nodiscard]] std::optional<std::string> validate() const {
    return first_problem(
        {rule::positive_finite("position_fraction", position_fraction),
         rule::check(max_position_fraction > 0.0, "max_position_fraction", max_position_fraction,
                     "must be > 0 (infinity: no wall)"),
         rule::positive_finite("velocity_fraction", velocity_fraction),
         rule::positive_finite("initial_position_fraction", initial_position_fraction),
         rule::check(initial_position_fraction <= position_fraction, "initial_position_fraction",
                     initial_position_fraction, "must be <= position_fraction = {}",
                     position_fraction),
         rule::positive_finite("change_gate", change_gate),
         rule::at_least("change_window", change_window, Index{1}),
         rule::check(innovation_window >= 0 && innovation_window <= max_history,
                     "innovation_window", innovation_window,
                     "must lie in [0, max_history = {}] (0: off)", max_history),
         rule::check(change_lag >= change_window, "change_lag", change_lag,
                     "must be >= change_window = {}", change_window),
         rule::non_negative_finite("change_position_spread", change_position_spread),
         rule::non_negative_finite("change_velocity_spread", change_velocity_spread),
         rule::positive_finite("change_velocity_floor_fraction", change_velocity_floor_fraction),
         rule::non_negative_finite("change_position_floor_fraction",
                                   change_position_floor_fraction),
         rule::non_negative_finite("significance", significance),
         rule::check(misfit_window == 0 || misfit_window >= 3, "misfit_window", misfit_window,
                     "0 (the gate in units of σz alone) or >= 3"),
         rule::check(max_misfit_scale >= 1.0, "max_misfit_scale", max_misfit_scale,
                     "must be >= 1 (infinity: unbounded)"),
         rule::check(min_gate_unit > 0.0 && min_gate_unit <= 1.0, "min_gate_unit", min_gate_unit,
                     "must lie in (0, 1] (1: in units of σz² alone)"),
         rule::check(min_erring_gate_unit > 0.0 && min_erring_gate_unit <= 1.0,
                     "min_erring_gate_unit", min_erring_gate_unit,
                     "must lie in (0, 1] (1: in units of the misfit scale)"),
         rule::check(min_erring_fit_unit > 0.0 && min_erring_fit_unit <= 1.0, "min_erring_fit_unit",
                     min_erring_fit_unit, "must lie in (0, 1] (1: the fit in units of σz²)"),
         rule::check(max_history > change_lag, "max_history", max_history,
                     "must be > change_lag = {}", change_lag),
         rule::at_least("max_iterations", max_iterations, 1),
         rule::positive_finite("step_tolerance", step_tolerance)});
  }
};

}  // namespace twincal
