// The plot of every simulated rubric test, for every lab, with no code of the lab's own: what it
// shows is derived from the rubric test, its metric's definition (the lab's metric_docs) and the
// lab's trace columns and units; the metric's time window is hatched where it does not count.
#pragma once
#include <map>
#include <string>

#include "grading/metric_doc.h"
#include "grading/report.h"
#include "grading/rubric.h"
#include "grading/scenario.h"
#include "labs/lab.h"

namespace dyn {

// What rubric.tests[i] (a test of a simulated metric) plots, the first of:
//   1. the test's own "plot";
//   2. the "plot" of another test of the same metric (its band, if that was the other test's
//      full-credit threshold, becomes this test's);
//   3. the trace columns the metric's definition names ("RMS of the tracking error x_c − x_d":
//      x_c against the reference x_d), with a band of ± the full-credit threshold when the metric
//      has the columns' unit;
//   4. the columns the watchdog watches; 5. "energy" (every lab has it).
// The y label is the rubric's, else the columns with their units ("x_c, x_d (m)"); the window is
// the metric's "from"/"to". A plot with an "x" column is an x–y plot (the path in the plane): its
// x label likewise, equal scales when both axes have one unit, and no window hatched.
TestPlotPlan planTestPlot(const Rubric& rubric, std::size_t i, const std::map<std::string, MetricDoc>& docs,
                          const Lab& lab);

// Writes out_dir/plots/NN-<slug>.png (width × height) for every test with a plan whose run has a
// trace, and records its path and bytes in the test.
void writeTestPlots(GradeReport& r, const std::map<std::string, ScenarioRun>& runs, const std::string& out_dir,
                    int width_px, int height_px);

}  // namespace dyn
