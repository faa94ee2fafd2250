#pragma once
/// @file
/// Everything the `twincal::twincal` target links, in one include: every module's umbrella
/// header. For a smaller build, include a module's umbrella (twincal/<module>/<module>.hpp) or a
/// single header instead.

#include "twincal/calculix/calculix.hpp"
#include "twincal/controllers/controllers.hpp"
#include "twincal/core/core.hpp"
#include "twincal/external/external.hpp"
#include "twincal/filters/filters.hpp"
#include "twincal/models/models.hpp"
#include "twincal/samplers/samplers.hpp"
#include "twincal/sheet_metal/sheet_metal.hpp"
