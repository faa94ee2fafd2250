#pragma once
/// @file
/// `SheetMetalLayout`: the geometry of a two-part lap-joint assembly and its fixture: the two
/// flat parts (an upper and a lower one, overlapping in a flange strip where the spot welds sit),
/// each part's adjustable locators (one clamp per locator holds the part on it), the weld points,
/// the key measurement points, the final supports and the two modelling choices that decide how
/// the locator adjustment u reaches the final shape (see docs/sheet_metal.md, "Sheet-metal twin").
///
/// Both parts are meshed with square elements of `element_size` on one global grid, so weld
/// points in the flange are nodes of both meshes. Every point must be a node of its part.

#include <optional>
#include <string>
#include <vector>

#include "twincal/core/eigen.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"

namespace twincal {

/// Which part a point belongs to.
enum class SheetMetalPart { upper, lower };

/// After release the assembly rests on ...
enum class FinalSupport {
  adjusted_locators,  ///< ... its adjusted locators (measured in the fixture): w = nominal + u
  nominal_frame,      ///< ... nominal supports: a 3-2-1 frame (3) or N-2-1 (N > 3)
};

/// What a spot weld ties once it is formed.
enum class WeldTie {
  translation,               ///< the normal displacement of the two sheets
  translation_and_rotation,  ///< and their two rotations (the nugget freezes the relative angle)
};

/// The plate degrees of freedom a weld ties under `tie`, as PlateMesh::dof components: 0 (w), or
/// 0, 1, 2 (w, θx, θy).
[[nodiscard]] std::vector<Index> tied_components(WeldTie tie);

/// A named point of one part (a locator, a key point, a support).
struct LayoutPoint {
  std::string name;
  SheetMetalPart part = SheetMetalPart::lower;
  double x = 0.0;  ///< mm
  double y = 0.0;  ///< mm
};

/// An axis-aligned rectangle [x0, x0 + width] × [y0, y0 + height] (mm).
struct PartOutline {
  double x0 = 0.0;
  double y0 = 0.0;
  double width = 0.0;
  double height = 0.0;
};

struct SheetMetalLayout {
  std::string name;
  double element_size = 20.0;  ///< mm, square ACM elements
  PartOutline upper;
  PartOutline lower;
  std::vector<LayoutPoint> locators;    ///< the d adjustable locators, in control order
  std::vector<Vector<2>> welds;         ///< (x, y) of each spot weld, in the overlap
  std::vector<LayoutPoint> key_points;  ///< the m measurement points
  std::vector<LayoutPoint> supports;    ///< >= 3 nominal supports (nominal_frame only)
  FinalSupport final_support = FinalSupport::adjusted_locators;
  WeldTie weld_tie = WeldTie::translation;

  /// The 'car body' case: 12 locators, final shape measured in the adjusted fixture.
  [[nodiscard]] static SheetMetalLayout body();
  /// The 'car door' case: 19 locators, release onto a nominal frame, rotation-locking welds.
  [[nodiscard]] static SheetMetalLayout door();

  /// A small lap joint for quick solves and tests ('lap-joint'): two 400 × 200 mm parts on a
  /// 40 mm grid overlapping in an 80 mm flange (rows y = 120, 160, 200), five welds on its
  /// middle row, three locators per part, eight key points in and away from the flange; measured
  /// in the fixture on its adjusted locators with translation welds (the body's choices).
  [[nodiscard]] static SheetMetalLayout lap_joint();
  /// Supports S1, S2, … at the nominal positions of the named locators, in order: a nominal
  /// frame under them for FinalSupport::nominal_frame.
  /// @throws InvalidArgumentError naming a locator the layout does not have.
  [[nodiscard]] std::vector<LayoutPoint> supports_at(
      const std::vector<std::string>& locator_names) const;
  /// d: the number of adjustable locators.
  [[nodiscard]] Index control_dimension() const noexcept {
    return static_cast<Index>(locators.size());
  }
  /// m: the number of key measurement points.
  [[nodiscard]] Index key_point_count() const noexcept {
    return static_cast<Index>(key_points.size());
  }
  /// The mesh of one part.
  /// @throws InvalidArgumentError when the outline is not a whole number of elements.
  [[nodiscard]] PlateMesh mesh(SheetMetalPart part) const;

  /// Consistency: positive sizes, outlines that are whole numbers of elements on a shared grid,
  /// at least three locators per part and non-empty welds and key points, all points on their
  /// parts, welds in the overlap and not on a locator, at least three supports for a nominal frame,
  /// unique locator names.
  [[nodiscard]] std::optional<std::string> validate() const;

  /// The layout as JSON (outlines, element size, locators, welds, key points, supports, the two
  /// modelling choices), for pictures and for other programs.
  [[nodiscard]] std::string to_json() const;
};

}  // namespace twincal
