#pragma once
// A render split over ranks reports one image and one set of counts (the render library
// sums them), and each rank's own times: what it spent in each phase shows where the
// split stops paying (docs/cluster.md).
#include "src/core/collective.h"
#include "src/render/report.h"

namespace lvox {

// Collective: gathers every rank's host, phase times and work (Report::work) into the root's report
// (its "ranks" array, report.h). Does nothing in one process.
void collectRankTimes(Collective& team, Report& report);

// At the root: one line per rank, "rank R (HOST): phase S s, ...".
void printRankTimes(const Report& report);

}  // namespace lvox
