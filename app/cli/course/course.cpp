// The course commands' command-line options; see course.h.
#include "app/cli/course/course.h"

namespace dyn::app {

CourseCommands::CourseCommands(CLI::App& cli) {
  HandoutArgs& h = handout_args_;
  handout_ = cli.add_subcommand("handout", "Write a lab's student handout (Markdown and self-contained HTML) from its JSON "
                                           "and labs/LAB/handout.md: mechanism, exercise, gains, submission, rubric, how to "
                                           "run, tune and self-grade");
  handout_->add_option("LAB", h.lab, "Lab name (see `dynlab list`)")->required();
  handout_->add_option("--out", h.out, "Output directory (default: out/LAB/handout)");
  handout_->add_option("--config", h.config, "Lab config JSON with the rubric (default: labs/LAB/LAB.json)");
  handout_->add_option("--student", h.student, "Write this student's handout: their plant's numbers and their key (the lab's "
                                               "variants; needs DYNLAB_COURSE_SECRET, or DYNLAB_STUDENT_KEY)");
  handout_->add_option("--format", h.format, "Comma-separated formats: md, html (default: md,html); for a PDF, open the HTML in a browser and print it (Save as PDF)");

  MapArgs& m = map_args_;
  map_ = cli.add_subcommand("map", "Stability/score map over two gains or parameters, from the screening (fast) or "
                                   "simulation (--sim), the screening's boundary drawn over it (PDF/SVG/PNG)");
  map_->add_option("LAB", m.lab, "Lab name (see `dynlab list`)")->required();
  map_->add_option("--x", m.x, "Horizontal axis GAIN=a:b:n (a gain, a parameter alias of the lab's JSON, or a JSON "
                               "pointer such as /controller/delay; n points from a to b, 2 ≤ n ≤ 200)")->required();
  map_->add_option("--y", m.y, "Vertical axis, as --x")->required();
  map_->add_option("--metric", m.metric, "Colour by this metric (a screening metric, or with --sim any rubric metric); "
                                         "default: stable or unstable");
  map_->add_option("--out", m.out, "Picture to write: .pdf, .svg or .png (default: out/LAB/map.pdf)");
  map_->add_option("--data", m.data, "Also write the grid as CSV (x, y, screening and simulated results)");
  map_->add_option("--config", m.config, "Lab config JSON (default: labs/LAB/LAB.json)");
  map_->add_option("--gains", m.gains, "Start from these gains and options: a submission or gains JSON");
  map_->add_flag("--sim", m.sim, "Also simulate every grid point (hand engine under the rubric's watchdog)");
  map_->add_option("--duration", m.duration, "Simulated duration per point with --sim (s; default: the lab's)");
  map_->add_option("--jobs", m.jobs, "Threads for --sim (default: every core)")->check(CLI::Range(1, 256));
}

int CourseCommands::run() const { return *handout_ ? handout(handout_args_) : map(map_args_); }

}  // namespace dyn::app
