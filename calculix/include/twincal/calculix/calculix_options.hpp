#pragma once
/// @file
/// `CalculixOptions`: how the CalculiX assembly twin meshes, loads and solves a lap joint
/// (docs/calculix.md). One declaration per setting: its default and its documentation.

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>

#include "twincal/core/eigen.hpp"
#include "twincal/sheet_metal/plate_section.hpp"

namespace twincal {

struct CalculixOptions {
  /// The CalculiX solver: a path, or a name looked up in PATH (Debian: calculix-ccx).
  std::string executable = "ccx";
  /// Where each solve gets a scratch directory of its own (removed after the solve).
  std::filesystem::path scratch_root = std::filesystem::temp_directory_path();
  /// Keep the scratch directories (deck, log, results) for inspection.
  bool keep_files = false;
  /// Elements per layout element edge: the CalculiX mesh has element_size / refinement.
  Index refinement = 1;
  /// Material and thickness of both sheets (one layer of C3D8I solids through the thickness).
  PlateSection section{};
  /// Node-to-node unilateral contact (GAPUNI) between the facing flange nodes.
  bool contact = true;
  /// Clearance between the sheets at nominal shape (mm); the welds close it (their nuggets).
  double nominal_gap = 0.02;
  /// Penalty stiffness of a closed gap (N/mm).
  double gap_stiffness = 1e4;
  /// The pull an open gap keeps at infinite opening (N): CalculiX's default, 1e-3 N, bends a
  /// 0.8 mm flange by 1e-5 mm, so open gaps would still move Q in its fourth digit.
  double open_gap_force = 1e-8;
  /// Large-displacement kinematics (*STEP, NLGEOM). CalculiX solves gap elements only in a
  /// nonlinear step, so contact requires it.
  bool geometric_nonlinearity = true;
  /// Most increments per step of a nonlinear solve before CalculiX gives up.
  Index max_increments = 100;
  /// Newton iterations of an increment before CalculiX cuts it back (its I_C; default 16).
  /// With CalculiX's defaults a lap-joint contact solve at a corner-ish control (assembly
  /// (2, 0), u = (0.67, 0, 0, −0.67, 0, 0.67)) ended in "too many cutbacks"; with these two
  /// it converges in 1.2 s.
  Index max_iterations = 200;
  /// Cutbacks of one increment before CalculiX gives up (its I_A; default 5).
  Index max_cutbacks = 20;
  /// Half the locator box: every locator moves within [−locator_bound, locator_bound] (mm).
  double locator_bound = 1.0;
  /// Threads one CalculiX process uses (equation solver and element loops).
  Index solver_threads = 1;
  /// A CalculiX run that takes longer is killed and reported as `timeout`.
  std::chrono::milliseconds timeout{std::chrono::minutes(10)};

  /// One line per rule: "<field>: value is <v>; rule: <rule>".
  [[nodiscard]] std::optional<std::string> validate() const;
};

}  // namespace twincal
