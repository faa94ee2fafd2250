#pragma once
/// @file
/// Umbrella header of the external module: twins that are other programs (the JSON-lines
/// protocol of docs/external.md), one process or a pool.

#include "twincal/external/child_groups.hpp"
#include "twincal/external/external_twin.hpp"
#include "twincal/external/external_twin_backend.hpp"
#include "twincal/external/external_twin_failure.hpp"
#include "twincal/external/external_twin_pool.hpp"
#include "twincal/external/twin_reply.hpp"
