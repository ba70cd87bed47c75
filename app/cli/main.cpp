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

// Every command's arguments and its subcommand (null until added); the adders below fill it, in the
// order `dynlab --help` lists them, and runChosen runs the one the command line chose.
struct Commands {
  CLI::App *list = nullptr, *r = nullptr, *f = nullptr, *g = nullptr, *z = nullptr, *c = nullptr, *s = nullptr,
           *sf = nullptr, *u = nullptr, *k = nullptr, *l = nullptr, *cl = nullptr, *nl = nullptr, *b = nullptr;
  dyn::app::RunArgs run;
  dyn::app::FigureArgs fig;
  dyn::app::GradeArgs grade;
  std::string zip_lab, zip_out = "autograder.zip";
  std::string results_file, schema_lab, upload_dir;
  dyn::app::UiArgs ui;
  dyn::app::CompareArgs cmp;
  dyn::app::LessonsArgs les;
  dyn::app::CheckLabArgs check_lab;
  dyn::app::NewLabArgs new_lab;
  dyn::app::BenchArgs bench_args;
};

// list and run: a lab (or a model file) run with both engines.
void addRun(CLI::App& cli, Commands& x) {
  x.list = cli.add_subcommand("list", "List the labs, one line each");

  x.r = cli.add_subcommand("run", "Run a lab with the hand-written dynamics and/or Bullet; write traces, summary, video");
  x.r->add_option("LAB", x.run.lab, "Lab name (see `dynlab list`), or an MJCF (.xml) / URDF (.urdf) model file: run as "
                                "`dynlab model FILE` does")->required();
  x.r->add_option("--config", x.run.config, "Lab config JSON (default: labs/LAB/LAB.json)");
  x.r->add_option("--gains", x.run.gains, "Gains JSON: {\"gains\": {...}} as in a submission");
  x.r->add_option("--out", x.run.out, "Output directory (default: out/LAB)");
  x.r->add_option("--engine", x.run.engine, "Which engine(s) to run")->check(CLI::IsMember({"hand", "bullet", "both"}));
  x.r->add_flag("--video", x.run.video, "Write video.mp4 (H.264, 30 fps)");
  x.r->add_flag("--frames", x.run.frames, "Write frames/NNNNN.png (30 fps)");
  x.r->add_option("--duration", x.run.duration, "Override the simulated duration (s)");
  x.r->add_option("--student", x.run.student, kStudentHelp);
  x.r->add_option("--scenario", x.run.scenario, "Run under one rubric scenario (heavy_load, noisy_sensor, ...) exactly as the "
                                          "grader does: its patch and the noise seed the gains file is graded with "
                                          "(default out: out/LAB/scenarios/NAME)");
  x.r->add_option("--torque", x.run.torques, "A model file only: a constant joint torque JOINT=VALUE (N·m; N on a slide), "
                                         "repeatable (default: passive)")->allow_extra_args(false);
  x.r->add_option("--loops", x.run.loops, "A model file only: loop closures beside it (JSON; default: STEM.loops.json beside a .urdf)");
  x.r->add_option("--dt", x.run.dt, "A model file only: the fixed step (s, 1e-5 to 1e-2; default: the file's <option timestep>)");
  dyn::app::addModelFileOptions(x.r, x.run.model_files);
}

// figure: lecture plots and stills from a run.
void addFigure(CLI::App& cli, Commands& x) {
  x.f = cli.add_subcommand("figure", "Lecture figures from a lab's run: plots of trace columns (PDF/SVG/PNG) and "
                                         "rendered stills (PNG); without --plot/--still, the lab's own plots (its "
                                         "rubric's and its JSON's \"figures\") and stills at the start, middle "
                                         "and end");
  x.f->add_option("LAB", x.fig.lab, "Lab name (see `dynlab list`)")->required();
  x.f->add_option("--config", x.fig.config, "Lab config JSON (default: labs/LAB/LAB.json)");
  x.f->add_option("--gains", x.fig.gains, "Gains JSON: {\"gains\": {...}} as in a submission (repeatable: each file a run, "
                                     "overlaid on every plot and named in the legend by its file, e.g. damper vs spring)")
      ->allow_extra_args(false);
  x.f->add_option("--duration", x.fig.duration, "Override the simulated duration (s)");
  x.f->add_option("--student", x.fig.student, kStudentHelp);
  x.f->add_option("--engine", x.fig.engine, "Which engine(s) to run: hand solid, Bullet dashed (plots) or as a ghost (stills)")
      ->check(CLI::IsMember({"hand", "bullet", "both"}));
  x.f->add_option("--out", x.fig.out, "Output directory (default: out/LAB/figures)");
  x.f->add_option("--plot", x.fig.plots, "Trace columns to plot against t, e.g. theta,theta_d, or Y:X for column Y "
                                     "against column X, e.g. \"y:x, y_d:x_d\" (the path in the plane; equal scales "
                                     "when both axes have one unit); a curve followed by @M is drawn only where "
                                     "column M is nonzero, e.g. \"y_p:x_p@contact\" (repeatable: one plot each); "
                                     "written as plot_<cols joined by +>.<format> (Y:X as Y-vs-X, @M as -where-M)")
      ->allow_extra_args(false);
  x.f->add_option("--still", x.fig.stills, "Render the scene at this time (s), nearest trace row (repeatable); "
                                       "written as still_<t>.png")
      ->allow_extra_args(false);
  x.f->add_option("--format", x.fig.format, "Plot format: pdf, svg or png (default: pdf)");
  x.f->add_option("--size", x.fig.size, "Size WIDTHxHEIGHT in pixels of the stills and the plots (a PDF or SVG page in "
                                    "points; default: stills 1920x1080, plots 800x450)");
  x.f->add_option("--font-scale", x.fig.font_scale, "Plot text size relative to the default for the plot's size (default: 1)")
      ->check(CLI::Range(0.25, 8.0));
  x.f->add_option("--y-scale", x.fig.y_scale, "Plot y axis: auto (log when the data are positive and span over 3 decades, "
                                          "e.g. a constraint residual), linear or log (default: auto)")
      ->check(CLI::IsMember({"auto", "linear", "log"}));
  x.f->add_flag("!--no-overlay", x.fig.overlay, "Stills without the overlay panel");
  x.f->add_option("--title", x.fig.title, "Title of every plot and of the stills' panel (default: the lab and columns)");
  x.f->add_option("--scenario", x.fig.scenario, "Run under one rubric scenario exactly as the grader does "
                                          "(default out: out/LAB/scenarios/NAME/figures)");
  dyn::app::addModelFileOptions(x.f, x.fig.model_files);
}

// grade: one submission, a replay, or a whole folder.
void addGrade(CLI::App& cli, Commands& x) {
  x.g = cli.add_subcommand("grade", "Grade a submission (gains JSON) against its lab's rubric, or a whole directory");
  x.g->add_option("SUBMISSION", x.grade.submission, "Submission JSON: {\"lab\": ..., \"gains\": {...}}");
  x.g->add_option("--out", x.grade.out, "Output directory: results.json, report.md/html, plots/ (default: out/grade)");
  x.g->add_option("--lab", x.grade.lab, "The assignment's lab: a submission naming another lab scores 0");
  x.g->add_option("--config", x.grade.config, "Lab config JSON with the rubric (default: labs/LAB/LAB.json)");
  x.g->add_option("--time-budget", x.grade.time_budget, "Wall-time budget per submission (s)")->check(timeBudget());
  x.g->add_option("--student", x.grade.student, kStudentHelp);
  x.g->add_option("--student-from", x.grade.student_from, "Gradescope's submission_metadata.json: grade on its submitter's "
                                                      "plant (their Student ID, else e-mail), when the --lab has variants");
  x.g->add_option("--roster", x.grade.roster, "--batch: a CSV whose rows are FILE_OR_FOLDER,STUDENT_ID (default: each "
                                          "folder's or file's own name is the student's ID when the lab has variants)");
  x.g->add_flag("!--no-plots", x.grade.plots, "Skip the response plots (faster)");
  x.g->add_flag("--inline-plots", x.grade.inline_plots, "Put each test's plot in results.json as an inline PNG (Gradescope shows "
                                                    "it to the student; 30-100 KB a plot, at most 600 KB in all)");
  x.g->add_option("--replay", x.grade.replay, "Re-grade SUBMISSION and check it matches this results.json");
  x.g->add_option("--batch", x.grade.batch, "Grade every *.json in this directory, and each folder below it as one student (a Gradescope export); --jobs grader processes, each submission graded as `dynlab grade` grades it");
  x.g->add_option("--jobs", x.grade.jobs, "Submissions graded in parallel with --batch")->check(CLI::Range(1, 256));
  x.g->callback([&] {
    if (x.grade.batch.empty() && x.grade.submission.empty())
      throw CLI::ValidationError("SUBMISSION", "give a submission file, or --batch DIR");
  });
}

// autograder, check-results, schema, submission-file: the files a course hands around.
void addCourseFiles(CLI::App& cli, Commands& x) {
  x.z = cli.add_subcommand("autograder", "Write a Gradescope autograder zip for a lab");
  x.z->add_option("LAB", x.zip_lab, "Lab name")->required();
  x.z->add_option("--out", x.zip_out, "Zip file to write (default: autograder.zip)");

  x.c = cli.add_subcommand("check-results", "Check that a results.json has the shape Gradescope accepts "
                                                "(exit 0 valid, 2 invalid with the JSON path)");
  x.c->add_option("FILE", x.results_file, "The results.json to check")->required();

  x.s = cli.add_subcommand("schema", "Print the JSON Schema of a lab's submission");
  x.s->add_option("LAB", x.schema_lab, "Lab name")->required();

  x.sf = cli.add_subcommand("submission-file", "Print which file of an upload folder is graded (the rule the batch and "
                                                   "run_autograder share), or why none is (exit 2)");
  x.sf->add_option("DIR", x.upload_dir, "The student's upload folder")->required();
}

// ui: the tuning window (dynlab-ui).
void addUi(CLI::App& cli, Commands& x) {
  x.u = cli.add_subcommand("ui", "Tune a lab's gains in a window and watch it move (runs dynlab-ui; options after LAB "
                                     "go to it, see `dynlab-ui --help`)");
  x.u->add_option("LAB", x.ui.lab, "Lab name (see `dynlab list`)")->required();
  x.u->add_option("--config", x.ui.config, "Lab config JSON (default: labs/LAB/LAB.json)");
  x.u->add_option("--gains", x.ui.gains, "Start from these gains: a submission or gains JSON");
  x.u->add_option("--scenario", x.ui.scenario, "Tune under one rubric scenario (its patch and the grader's noise seed)");
  x.u->add_option("--student", x.ui.student, kStudentHelp);
  x.u->allow_extras();
}

// compare and lessons: submissions graded side by side, and the rubric's lesson pairs.
void addCompareLessons(CLI::App& cli, Commands& x) {
  x.k = cli.add_subcommand("compare", "Grade two submissions (gain sets) of one lab with the same rubric, side by side: "
                                          "a table per test, OUT/comparison.md and one plot per simulated test with both responses");
  x.k->add_option("A", x.cmp.a, "First submission JSON")->required();
  x.k->add_option("B", x.cmp.b, "Second submission JSON")->required();
  x.k->add_option("--out", x.cmp.out, "Output directory: comparison.md, plots/ (default: out/compare)");
  x.k->add_option("--lab", x.cmp.lab, "The lab both must name (default: the lab A names)");
  x.k->add_option("--config", x.cmp.config, "Lab config JSON with the rubric (default: labs/LAB/LAB.json)");
  x.k->add_option("--time-budget", x.cmp.time_budget, "Wall-time budget per submission (s)")->check(timeBudget());
  x.k->add_flag("!--no-plots", x.cmp.plots, "Skip the plots (faster)");

  x.l = cli.add_subcommand("lessons", "Grade the rubric's lesson pairs (the lecture's preferred design against its "
                                          "foil) and check each ranks as the lecture says (exit 1 if one does not)");
  x.l->add_option("LAB", x.les.lab, "Lab name (see `dynlab list`)")->required();
  x.l->add_option("--config", x.les.config, "Lab config JSON with the rubric (default: labs/LAB/LAB.json); the pairs' paths are "
                                        "relative to its folder");
  x.l->add_option("--time-budget", x.les.time_budget, "Wall-time budget per submission (s)")->check(timeBudget());
}

// check-lab and new-lab: a lecturer's tools.
void addAuthoring(CLI::App& cli, Commands& x) {
  x.cl = cli.add_subcommand("check-lab", "Check one lab against the lab contract the every-lab test holds every lab to: "
                                             "each check with ok/FAIL and a reason, the default gains', examples' and instructor "
                                             "answers' shares, the passive energy drift (exit 1 if a check fails)");
  x.cl->add_option("LAB", x.check_lab.lab, "Lab name (see `dynlab list`)")->required();
  x.cl->add_flag("--skip-cli", x.check_lab.skip_cli, "Skip running dynlab figure/run/grade on the lab as subprocesses (faster)");

  x.nl = cli.add_subcommand("new-lab", "Start a lab without C++: copy a data-defined lab's folder (JSON, model file, handout, "
                                           "examples) under a new name, to edit its JSON; then `dynlab check-lab NAME`");
  x.nl->add_option("NAME", x.new_lab.name, "The new lab's name (lowercase letters, digits, _)")->required();
  x.nl->add_option("--from", x.new_lab.from, "The data-defined lab to copy, e.g. fivebar")->required();
}

// bench: the step, the frame rates, the scaling.
void addBench(CLI::App& cli, Commands& x) {
  x.b = cli.add_subcommand("bench", "Benchmark: hand-written vs Bullet step time, render/PNG/video frame rates");
  x.b->add_flag("--json", x.bench_args.json, "One JSON object per lab");
  x.b->add_option("--steps", x.bench_args.steps, "Steps timed per engine")->check(CLI::Range(100, 1000000));
  x.b->add_option("--frames", x.bench_args.frames, "Frames timed per output kind")->check(CLI::Range(5, 10000));
  x.b->add_option("LAB", x.bench_args.lab, "Only this lab (default: every lab), or an MJCF/URDF model file: its hand step against "
                                      "Bullet's and MuJoCo's at equal order");
  x.b->add_flag("--scaling", x.bench_args.scaling,
              "Step cost against chain length (3 to 1,000 links): hand ABA, hand CRBA + Cholesky, Bullet; "
              "a table, OUT/scaling.csv and OUT/scaling.png");
  x.b->add_option("--out", x.bench_args.out, "--scaling: output directory (default: out/bench)");
  dyn::app::addModelFileOptions(x.b, x.bench_args.model_files);
}

// The chosen command, run: its exit code (2 when none was chosen, which CLI11 already refuses).
int runChosen(Commands& x, const dyn::app::LabOptions& lab_options) {
  using namespace dyn::app;
  x.new_lab.labs = lab_options.labs;
  if (*x.list) return listLabs();
  if (*x.r) {
    if (isModelFile(x.run.lab)) return runModelFile(x.run);
    if (!x.run.torques.empty() || !x.run.loops.empty() || x.run.dt) {
      std::fprintf(stderr, "error: <command line>: %s: a lab's torques come from its controller and its step from its config; --torque, "
                   "--loops and --dt are for a model file\n", x.run.dt ? "--dt" : x.run.torques.empty() ? "--loops" : "--torque");
      return 2;
    }
    if (const int refused = refuseModelFileFlags(x.run.lab, x.run.model_files)) return refused;
    return runLab(x.run);
  }
  if (*x.f) {
    if (!isModelFile(x.fig.lab) && refuseModelFileFlags(x.fig.lab, x.fig.model_files)) return 2;
    return figure(x.fig);
  }
  if (*x.g) return !x.grade.batch.empty() ? gradeBatch(x.grade) : !x.grade.replay.empty() ? gradeReplay(x.grade) : gradeOne(x.grade);
  if (*x.z) return writeAutograderZip(x.zip_lab, x.zip_out);
  if (*x.c) return checkResults(x.results_file);
  if (*x.s) return printSchema(x.schema_lab);
  if (*x.sf) return printSubmissionFile(x.upload_dir);
  if (*x.k) return compare(x.cmp);
  if (*x.l) return lessons(x.les);
  if (*x.cl) return checkLab(x.check_lab);
  if (*x.nl) return newLab(x.new_lab);
  if (*x.b) {
    if (!isModelFile(x.bench_args.lab) && refuseModelFileFlags(x.bench_args.lab, x.bench_args.model_files)) return 2;
    return x.bench_args.scaling ? benchScaling(x.bench_args) : bench(x.bench_args);
  }
  if (*x.u) {
    x.ui.extra = x.u->remaining();
    return openUi(x.ui);
  }
  return 2;
}

int dispatch(int argc, char** argv) {
  using namespace dyn::app;
  CLI::App cli{"dynlab — a teaching lab for the dynamics of constrained mechanisms"};
  cli.require_subcommand(1);
  cli.set_version_flag("--version", std::string(DYNLAB_VERSION));
  Commands x;
  for (auto add : {addRun, addFigure, addGrade, addCourseFiles, addUi, addCompareLessons, addAuthoring, addBench}) add(cli, x);
  CourseCommands course(cli);      // dynlab handout, dynlab map (app/cli/course/course.h)
  ModelCommand model_file(cli);    // dynlab model FILE (app/cli/model/model.h)
  LabOptions lab_options;          // --labs DIR on every command that names a lab (app/cli/lab_options.h)
  addLabOptions(cli, lab_options);

  requireFinite(cli);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : 2;
  }
  if (const int code = useLabOptions(lab_options)) return code;
  if (course.chosen()) return course.run();
  if (model_file.chosen()) return model_file.run();
  return runChosen(x, lab_options);
}
}  // namespace
