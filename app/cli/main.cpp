// dynlab: the command line. Dispatch only; the work is in labs/, grading/ and render/.
#include <CLI/CLI.hpp>

#include <csignal>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <new>
#include <string>

#include "app/cli/course/check_results.h"
#include "app/cli/commands.h"
#include "app/cli/course/course.h"
#include "app/cli/isolated_draw.h"
#include "app/cli/lab_options.h"
#include "app/cli/model/model.h"
#include "app/cli/course/submission_file.h"
#include "grading/grade.h"
#include "labs/utf8.h"

namespace {
int dispatch(int argc, char** argv);

// Exit code of an error that is dynlab's, not the input's: distinct from 1 (a run or write
// failed) and 2 (bad input), so a batch or the autograder can tell them apart.
constexpr int kInternalError = 3;

// --student on every command that runs or grades a lab's plant (labs/variants.h, grading/student.h).
constexpr const char* kStudentHelp =
    "Use this student's plant (the lab's variants, drawn from the student's key: DYNLAB_STUDENT_KEY, the key on "
    "their handout, or for staff DYNLAB_COURSE_SECRET); default: the nominal plant";

// What escaped every command, as one line of valid UTF-8 on stderr: a name or path it quotes
// (a model file's, say) escaped and clipped (termName), never a raw control character.
int internalError(const std::string& what) {
  std::fprintf(stderr, "error: internal: %s\n", dyn::termName(what, 1000).c_str());
  return kInternalError;
}

// Out of memory is the machine's limit, not dynlab's error: one line and exit 1 (a run or write failed).
// what: the library's own words, when it said so (one line, valid UTF-8).
int outOfMemory(const std::string& what = "the command needed more memory than it could get") {
  std::string line = dyn::utf8Quotable(what);
  for (char& c : line)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  std::fprintf(stderr, "error: out of memory: %s%s\n", line.c_str(), dyn::app::memoryLimitText().c_str());
  return 1;
}

// A library's own words for a failed allocation, in what escaped (MuJoCo's "Could not allocate memory").
bool saysOutOfMemory(const std::string& what) {
  for (const char* words : {"Could not allocate memory", "Cannot allocate memory", "out of memory"})
    if (what.find(words) != std::string::npos) return true;
  return false;
}
}  // namespace

// Standard output that could not be written (a full disk, /dev/full, a closed pipe): one line on
// stderr and a non-zero exit, never a success whose output was lost.
static int checkStdout(int code) {
  errno = 0;
  std::cout.flush();
  if (std::fflush(stdout) == 0 && !std::ferror(stdout) && !std::cout.fail()) return code;
  const int err = errno;
  std::fprintf(stderr, "error: cannot write standard output (%s)\n", err ? std::strerror(err) : "write failed");
  return code == 0 ? 1 : code;
}

// Whatever escapes a command is reported on one line and exits 3 (out of memory: 1): never an abort. A write past
// `ulimit -f` (SIGXFSZ) or into a closed pipe (SIGPIPE, `| head`) fails with an error the command
// reports instead of killing it, so a batch still writes its gradebook.
int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);
  std::signal(SIGXFSZ, SIG_IGN);
  int code;
  try {
    code = dispatch(argc, argv);
  } catch (const std::bad_alloc&) {
    code = outOfMemory();
  } catch (const std::exception& e) {
    code = saysOutOfMemory(e.what()) ? outOfMemory(e.what()) : internalError(e.what());
  } catch (...) {
    code = internalError("an exception that is not a std::exception");
  }
  return checkStdout(code);
}

namespace {
// --time-budget: the grader's own check and message (grading/grade.h), which dynlab.grade gives too.
CLI::Validator timeBudget() {
  return CLI::Validator(
      [](std::string& text) {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return std::string();  // not a number: CLI11's conversion says so
        return dyn::timeBudgetProblem(v);
      },
      "SECONDS");
}

// Every floating-point option of every command (CLI11 names their type FLOAT) refuses NaN and the
// infinities: a range check passes NaN (every comparison is false), and inf overflows what uses it.
void requireFinite(CLI::App& app) {
  const CLI::Validator finite(
      [](std::string& text) {
        const double v = std::strtod(text.c_str(), nullptr);
        return std::isfinite(v) ? std::string() : "expected a finite number, got \"" + text + "\"";
      },
      "FINITE");
  for (CLI::Option* o : app.get_options())
    if (o->get_type_name().find("FLOAT") != std::string::npos) o->check(finite);
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) requireFinite(*sub);
}

int dispatch(int argc, char** argv) {
  using namespace dyn::app;
  CLI::App cli{"dynlab — a teaching lab for the dynamics of constrained mechanisms"};
  cli.require_subcommand(1);
  cli.set_version_flag("--version", std::string(DYNLAB_VERSION));

  auto* list = cli.add_subcommand("list", "List the labs, one line each");

  RunArgs run;
  auto* r = cli.add_subcommand("run", "Run a lab with the hand-written dynamics and/or Bullet; write traces, summary, video");
  r->add_option("LAB", run.lab, "Lab name (see `dynlab list`), or an MJCF (.xml) / URDF (.urdf) model file: run as "
                                "`dynlab model FILE` does")->required();
  r->add_option("--config", run.config, "Lab config JSON (default: labs/LAB/LAB.json)");
  r->add_option("--gains", run.gains, "Gains JSON: {\"gains\": {...}} as in a submission");
  r->add_option("--out", run.out, "Output directory (default: out/LAB)");
  r->add_option("--engine", run.engine, "Which engine(s) to run")->check(CLI::IsMember({"hand", "bullet", "both"}));
  r->add_flag("--video", run.video, "Write video.mp4 (H.264, 30 fps)");
  r->add_flag("--frames", run.frames, "Write frames/NNNNN.png (30 fps)");
  r->add_option("--duration", run.duration, "Override the simulated duration (s)");
  r->add_option("--student", run.student, kStudentHelp);
  r->add_option("--scenario", run.scenario, "Run under one rubric scenario (heavy_load, noisy_sensor, ...) exactly as the "
                                          "grader does: its patch and the noise seed the gains file is graded with "
                                          "(default out: out/LAB/scenarios/NAME)");
  r->add_option("--torque", run.torques, "A model file only: a constant joint torque JOINT=VALUE (N·m; N on a slide), "
                                         "repeatable (default: passive)")->allow_extra_args(false);
  r->add_option("--loops", run.loops, "A model file only: loop closures beside it (JSON; default: STEM.loops.json beside a .urdf)");

  FigureArgs fig;
  auto* f = cli.add_subcommand("figure", "Lecture figures from a lab's run: plots of trace columns (PDF/SVG/PNG) and "
                                         "rendered stills (PNG); without --plot/--still, the lab's own plots (its "
                                         "rubric's and its JSON's \"figures\") and stills at the start, middle "
                                         "and end");
  f->add_option("LAB", fig.lab, "Lab name (see `dynlab list`)")->required();
  f->add_option("--config", fig.config, "Lab config JSON (default: labs/LAB/LAB.json)");
  f->add_option("--gains", fig.gains, "Gains JSON: {\"gains\": {...}} as in a submission (repeatable: each file a run, "
                                     "overlaid on every plot and named in the legend by its file, e.g. damper vs spring)")
      ->allow_extra_args(false);
  f->add_option("--duration", fig.duration, "Override the simulated duration (s)");
  f->add_option("--student", fig.student, kStudentHelp);
  f->add_option("--engine", fig.engine, "Which engine(s) to run: hand solid, Bullet dashed (plots) or as a ghost (stills)")
      ->check(CLI::IsMember({"hand", "bullet", "both"}));
  f->add_option("--out", fig.out, "Output directory (default: out/LAB/figures)");
  f->add_option("--plot", fig.plots, "Trace columns to plot against t, e.g. theta,theta_d, or Y:X for column Y "
                                     "against column X, e.g. \"y:x, y_d:x_d\" (the path in the plane; equal scales "
                                     "when both axes have one unit); a curve followed by @M is drawn only where "
                                     "column M is nonzero, e.g. \"y_p:x_p@contact\" (repeatable: one plot each); "
                                     "written as plot_<cols joined by +>.<format> (Y:X as Y-vs-X, @M as -where-M)")
      ->allow_extra_args(false);
  f->add_option("--still", fig.stills, "Render the scene at this time (s), nearest trace row (repeatable); "
                                       "written as still_<t>.png")
      ->allow_extra_args(false);
  f->add_option("--format", fig.format, "Plot format: pdf, svg or png (default: pdf)");
  f->add_option("--size", fig.size, "Size WIDTHxHEIGHT in pixels of the stills and the plots (a PDF or SVG page in "
                                    "points; default: stills 1920x1080, plots 800x450)");
  f->add_option("--font-scale", fig.font_scale, "Plot text size relative to the default for the plot's size (default: 1)")
      ->check(CLI::Range(0.25, 8.0));
  f->add_option("--y-scale", fig.y_scale, "Plot y axis: auto (log when the data are positive and span over 3 decades, "
                                          "e.g. a constraint residual), linear or log (default: auto)")
      ->check(CLI::IsMember({"auto", "linear", "log"}));
  f->add_flag("!--no-overlay", fig.overlay, "Stills without the overlay panel");
  f->add_option("--title", fig.title, "Title of every plot and of the stills' panel (default: the lab and columns)");
  f->add_option("--scenario", fig.scenario, "Run under one rubric scenario exactly as the grader does "
                                          "(default out: out/LAB/scenarios/NAME/figures)");

  GradeArgs grade;
  auto* g = cli.add_subcommand("grade", "Grade a submission (gains JSON) against its lab's rubric, or a whole directory");
  g->add_option("SUBMISSION", grade.submission, "Submission JSON: {\"lab\": ..., \"gains\": {...}}");
  g->add_option("--out", grade.out, "Output directory: results.json, report.md/html, plots/ (default: out/grade)");
  g->add_option("--lab", grade.lab, "The assignment's lab: a submission naming another lab scores 0");
  g->add_option("--config", grade.config, "Lab config JSON with the rubric (default: labs/LAB/LAB.json)");
  g->add_option("--time-budget", grade.time_budget, "Wall-time budget per submission (s)")->check(timeBudget());
  g->add_option("--student", grade.student, kStudentHelp);
  g->add_option("--student-from", grade.student_from, "Gradescope's submission_metadata.json: grade on its submitter's "
                                                      "plant (their Student ID, else e-mail), when the --lab has variants");
  g->add_option("--roster", grade.roster, "--batch: a CSV whose rows are FILE_OR_FOLDER,STUDENT_ID (default: each "
                                          "folder's or file's own name is the student's ID when the lab has variants)");
  g->add_flag("!--no-plots", grade.plots, "Skip the response plots (faster)");
  g->add_flag("--inline-plots", grade.inline_plots, "Put each test's plot in results.json as an inline PNG (Gradescope shows "
                                                    "it to the student; 30-100 KB a plot, at most 600 KB in all)");
  g->add_option("--replay", grade.replay, "Re-grade SUBMISSION and check it matches this results.json");
  g->add_option("--batch", grade.batch, "Grade every *.json in this directory, and each folder below it as one student (a Gradescope export); one process each");
  g->add_option("--jobs", grade.jobs, "Submissions graded in parallel with --batch")->check(CLI::Range(1, 256));
  g->callback([&] {
    if (grade.batch.empty() && grade.submission.empty())
      throw CLI::ValidationError("SUBMISSION", "give a submission file, or --batch DIR");
  });

  std::string zip_lab, zip_out = "autograder.zip";
  auto* z = cli.add_subcommand("autograder", "Write a Gradescope autograder zip for a lab");
  z->add_option("LAB", zip_lab, "Lab name")->required();
  z->add_option("--out", zip_out, "Zip file to write (default: autograder.zip)");

  std::string results_file;
  auto* c = cli.add_subcommand("check-results", "Check that a results.json has the shape Gradescope accepts "
                                                "(exit 0 valid, 2 invalid with the JSON path)");
  c->add_option("FILE", results_file, "The results.json to check")->required();

  std::string schema_lab;
  auto* s = cli.add_subcommand("schema", "Print the JSON Schema of a lab's submission");
  s->add_option("LAB", schema_lab, "Lab name")->required();

  std::string upload_dir;
  auto* sf = cli.add_subcommand("submission-file", "Print which file of an upload folder is graded (the rule the batch and "
                                                   "run_autograder share), or why none is (exit 2)");
  sf->add_option("DIR", upload_dir, "The student's upload folder")->required();

  UiArgs ui;
  auto* u = cli.add_subcommand("ui", "Tune a lab's gains in a window and watch it move (runs dynlab-ui; options after LAB "
                                     "go to it, see `dynlab-ui --help`)");
  u->add_option("LAB", ui.lab, "Lab name (see `dynlab list`)")->required();
  u->add_option("--config", ui.config, "Lab config JSON (default: labs/LAB/LAB.json)");
  u->add_option("--gains", ui.gains, "Start from these gains: a submission or gains JSON");
  u->add_option("--scenario", ui.scenario, "Tune under one rubric scenario (its patch and the grader's noise seed)");
  u->add_option("--student", ui.student, kStudentHelp);
  u->allow_extras();

  CompareArgs cmp;
  auto* k = cli.add_subcommand("compare", "Grade two submissions (gain sets) of one lab with the same rubric, side by side: "
                                          "a table per test, OUT/comparison.md and one plot per simulated test with both responses");
  k->add_option("A", cmp.a, "First submission JSON")->required();
  k->add_option("B", cmp.b, "Second submission JSON")->required();
  k->add_option("--out", cmp.out, "Output directory: comparison.md, plots/ (default: out/compare)");
  k->add_option("--lab", cmp.lab, "The lab both must name (default: the lab A names)");
  k->add_option("--config", cmp.config, "Lab config JSON with the rubric (default: labs/LAB/LAB.json)");
  k->add_option("--time-budget", cmp.time_budget, "Wall-time budget per submission (s)")->check(timeBudget());
  k->add_flag("!--no-plots", cmp.plots, "Skip the plots (faster)");

  LessonsArgs les;
  auto* l = cli.add_subcommand("lessons", "Grade the rubric's lesson pairs (the lecture's preferred design against its "
                                          "foil) and check each ranks as the lecture says (exit 1 if one does not)");
  l->add_option("LAB", les.lab, "Lab name (see `dynlab list`)")->required();
  l->add_option("--config", les.config, "Lab config JSON with the rubric (default: labs/LAB/LAB.json); the pairs' paths are "
                                        "relative to its folder");
  l->add_option("--time-budget", les.time_budget, "Wall-time budget per submission (s)")->check(timeBudget());

  CheckLabArgs check_lab;
  auto* cl = cli.add_subcommand("check-lab", "Check one lab against the lab contract the every-lab test holds every lab to: "
                                             "each check with ok/FAIL and a reason, the default gains', examples' and instructor "
                                             "answers' shares, the passive energy drift (exit 1 if a check fails)");
  cl->add_option("LAB", check_lab.lab, "Lab name (see `dynlab list`)")->required();
  cl->add_flag("--skip-cli", check_lab.skip_cli, "Skip running dynlab figure/run/grade on the lab as subprocesses (faster)");

  NewLabArgs new_lab;
  auto* nl = cli.add_subcommand("new-lab", "Start a lab without C++: copy a data-defined lab's folder (JSON, model file, handout, "
                                           "examples) under a new name, to edit its JSON; then `dynlab check-lab NAME`");
  nl->add_option("NAME", new_lab.name, "The new lab's name (lowercase letters, digits, _)")->required();
  nl->add_option("--from", new_lab.from, "The data-defined lab to copy, e.g. fivebar")->required();

  BenchArgs bench_args;
  auto* b = cli.add_subcommand("bench", "Benchmark: hand-written vs Bullet step time, render/PNG/video frame rates");
  b->add_flag("--json", bench_args.json, "One JSON object per lab");
  b->add_option("--steps", bench_args.steps, "Steps timed per engine")->check(CLI::Range(100, 1000000));
  b->add_option("--frames", bench_args.frames, "Frames timed per output kind")->check(CLI::Range(5, 10000));
  b->add_option("LAB", bench_args.lab, "Only this lab (default: every lab), or an MJCF/URDF model file: its hand step against "
                                      "Bullet's and MuJoCo's at equal order");
  b->add_flag("--scaling", bench_args.scaling,
              "Step cost against chain length (3 to 1,000 links): hand ABA, hand CRBA + Cholesky, Bullet; "
              "a table, OUT/scaling.csv and OUT/scaling.png");
  b->add_option("--out", bench_args.out, "--scaling: output directory (default: out/bench)");

  CourseCommands course(cli);  // dynlab handout, dynlab map (app/cli/course/course.h)
  ModelCommand model_file(cli);  // dynlab model FILE (app/cli/model/model.h)
  LabOptions lab_options;        // --labs DIR on every command that names a lab (app/cli/lab_options.h)
  addLabOptions(cli, lab_options);

  requireFinite(cli);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : 2;
  }
  if (const int code = useLabOptions(lab_options)) return code;
  new_lab.labs = lab_options.labs;
  if (*list) return listLabs();
  if (*r) {
    if (isModelFile(run.lab)) return runModelFile(run);
    if (!run.torques.empty() || !run.loops.empty()) {
      std::fprintf(stderr, "error: <command line>: %s: a lab's torques come from its controller; --torque and --loops are for a model file\n",
                   run.torques.empty() ? "--loops" : "--torque");
      return 2;
    }
    return runLab(run);
  }
  if (*f) return figure(fig);
  if (*g) return !grade.batch.empty() ? gradeBatch(grade) : !grade.replay.empty() ? gradeReplay(grade) : gradeOne(grade);
  if (*z) return writeAutograderZip(zip_lab, zip_out);
  if (*c) return checkResults(results_file);
  if (*s) return printSchema(schema_lab);
  if (*sf) return printSubmissionFile(upload_dir);
  if (*k) return compare(cmp);
  if (*l) return lessons(les);
  if (*cl) return checkLab(check_lab);
  if (*nl) return newLab(new_lab);
  if (*b) return bench_args.scaling ? benchScaling(bench_args) : bench(bench_args);
  if (course.chosen()) return course.run();
  if (model_file.chosen()) return model_file.run();
  if (*u) {
    ui.extra = u->remaining();
    return openUi(ui);
  }
  return 2;
}
}  // namespace
