#pragma once
/// @file
/// `write_history_csv`: a serve session's history as one CSV row per request, for a
/// spreadsheet or `twincal plot --history` (δû_t ± 2σ per locator and the quality over time).
///
/// Columns: request_id, upper, lower (the assembly), proposed_at, observed_at, quality (z_t),
/// optimal_quality (z*(x_t) of the twin), then per locator L: control_L (u_t), estimate_L (δû_t
/// after the observation) and sd_L (√P_t,LL). A request awaiting its observation has empty
/// observation fields; a controller without P (baseline, nominal) has empty sd_L.

#include <ostream>

#include "twincal/serve/history_store.hpp"

namespace twincal {

/// @throws HistoryStoreError when the history cannot be read.
void write_history_csv(const HistoryStore& store, std::ostream& out);

}  // namespace twincal
