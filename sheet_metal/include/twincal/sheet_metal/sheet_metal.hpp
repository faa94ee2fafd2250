#pragma once
/// @file
/// Umbrella header of the sheet_metal module: the open FEM twins of the car body and door
/// (linear and with contact), their plates, meshes, joining process, parts and solvers.

#include "twincal/sheet_metal/acm_plate_element.hpp"
#include "twincal/sheet_metal/constrained_solver.hpp"
#include "twincal/sheet_metal/contact_pairs.hpp"
#include "twincal/sheet_metal/contact_sheet_metal_twin.hpp"
#include "twincal/sheet_metal/contact_solver.hpp"
#include "twincal/sheet_metal/contact_solver_error.hpp"
#include "twincal/sheet_metal/part_deviation_file.hpp"
#include "twincal/sheet_metal/part_field.hpp"
#include "twincal/sheet_metal/plate_mesh.hpp"
#include "twincal/sheet_metal/plate_model.hpp"
#include "twincal/sheet_metal/plate_section.hpp"
#include "twincal/sheet_metal/release_stage.hpp"
#include "twincal/sheet_metal/sheet_metal_layout.hpp"
#include "twincal/sheet_metal/sheet_metal_process.hpp"
#include "twincal/sheet_metal/sheet_metal_twin.hpp"
