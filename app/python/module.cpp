// The `dynlab` Python module: list labs, load one, set and read its gains, run it (NumPy traces),
// screen and grade it — the CLI's commands over the same core, from a notebook.
//   import dynlab
//   lab = dynlab.Lab("slider_crank"); lab.set_gains(k_p=400)
//   r = lab.run(engine="both", duration=2)   # r["traces"]["hand"]["x"], r["engines"], r["agreement"]
//   img = lab.frame(1.0)                    # (480, 640, 3) uint8, the last run at t = 1 s
//   dynlab.grade(lab.submission())["score"]
//   dynlab.Lab("trammel", labs="~/course/labs")   # a lab outside the tree (the CLI's --labs DIR)
// Bad input raises dynlab.InputError (a ValueError) with the CLI's one-line message
// "<file>: <JSON path>: <what was expected>" and its parts as .file, .path, .expected.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "app/python/convert.h"
#include "app/python/lab_object.h"
#include "grading/grade.h"
#include "grading/student.h"
#include "labs/generic/lab_folders.h"

namespace py = pybind11;
using namespace dyn;
using namespace dyn::python;

namespace {

// labs=: a folder of lab folders outside the tree, or a list of them (the CLI's --labs DIR), then
// DYNLAB_LABS's, registered after the tree's labs for the rest of the process (labs/generic/lab_folders.h).
void useLabs(py::handle labs) {
  std::vector<generic::LabsFolder> folders;
  std::string path;
  if (!labs.is_none()) {
    if (asPath(labs, path)) {
      folders.push_back({path, "labs", kArgument});
    } else {
      if (!py::isinstance<py::sequence>(labs) || py::isinstance<py::str>(labs))
        throw py::type_error("labs: a folder (str or os.PathLike) or a list of them");
      for (py::handle item : labs) {
        if (!asPath(item, path)) throw py::type_error("labs: a folder (str or os.PathLike) or a list of them");
        folders.push_back({path, "labs", kArgument});
      }
    }
  }
  for (const auto& f : generic::labsFoldersFromEnvironment()) folders.push_back(f);
  generic::useLabsFolders(folders);
}

// dynlab.grade: a submission dict or file → results.json as a dict, as `dynlab grade` writes it
// (no plots). A submission the grader refuses raises InputError with `dynlab grade`'s message.
py::dict grade(py::handle submission, const std::string& lab, const std::string& config, double time_budget,
               const std::string& student) {
  // `dynlab grade --time-budget`'s check and message (NaN, inf, 0, -1, 1e300 are refused, not graded as out of time).
  if (const std::string problem = timeBudgetProblem(time_budget); !problem.empty())
    throw InputError(kArgument, "time_budget", problem);
  useLabs(py::none());  // DYNLAB_LABS's labs, as every command reads them
  GradeOptions o;
  o.expected_lab = lab;
  o.config_file = config;
  o.plant = studentPlant(student, "student", kArgument);
  o.time_budget = time_budget;
  std::string file;
  const bool is_file = asPath(submission, file);
  const json sub = is_file ? json() : toJson(submission, kSubmissionSource);
  Interruptible interrupted;
  o.stop = [&] { return interrupted(); };
  GradeOutcome g;
  {
    py::gil_scoped_release release;
    g = is_file ? gradeSubmission(file, o) : gradeSubmission(sub, kSubmissionSource, o);
  }
  interrupted.rethrow();
  if (g.input_error) {
    const json e = g.results["extra_data"].value("error", json::object());
    throw InputError(e.value("file", ""), e.value("path", ""), e.value("expected", ""));
  }
  if (g.internal_error) throw std::runtime_error(g.error);
  return toPython(g.results);
}

}  // namespace

// The module's contents (an embedding program can add them to its own interpreter too).
void dyn::python::defineModule(py::module_& m) {
  m.doc() = "dynlab: constrained-mechanism dynamics labs (hand-written engine beside Bullet) and their grader";
  m.attr("__version__") = DYNLAB_VERSION;

  // InputError: a ValueError carrying the CLI's message and its parts.
  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      py::object exc = py::handle(input_error.ptr())(e.what());
      exc.attr("file") = e.file();
      exc.attr("path") = e.path().empty() ? "/" : e.path();
      exc.attr("expected") = e.expected();
      PyErr_SetObject(input_error.ptr(), exc.ptr());
    }
  });

  m.def("labs", [](py::handle labs) {
    useLabs(labs);
    py::dict out;
    for (const auto& e : labRegistry()) out[py::str(e.name)] = e.summary;
    return out;
  }, py::arg("labs") = py::none(),
     "Every lab: name → one-line summary (dynlab list); labs=DIR (or a list) adds the labs of a folder outside the "
     "dynlab tree, as --labs DIR does (DYNLAB_LABS is read too).");

  py::class_<LabObject>(m, "Lab", "One lab: its config, the gains set so far, runs and screening.")
      .def(py::init([](const std::string& name, const std::string& config, py::handle labs, const std::string& student) {
             useLabs(labs);
             return LabObject(name, config, student);
           }),
           py::arg("name"), py::arg("config") = "", py::arg("labs") = py::none(), py::arg("student") = "",
           "Loads lab NAME with its default config, or the config file given (dynlab run LAB --config F); labs=DIR "
           "(or a list) finds NAME in a folder of lab folders outside the dynlab tree too (dynlab run LAB --labs DIR); "
           "on STUDENT's plant when given (the lab's variants; DYNLAB_STUDENT_KEY or DYNLAB_COURSE_SECRET must be set).")
      .def_property_readonly("student", &LabObject::student, "Whose plant ('' the nominal one).")
      .def_property_readonly("name", &LabObject::name)
      .def_property_readonly("config", &LabObject::configFile, "The config file the lab was loaded from.")
      .def_property_readonly("gains", &LabObject::gains, "Current gains: name → value.")
      .def_property_readonly("gain_info", &LabObject::gainInfo, "Each gain's value, min, max, unit and doc.")
      .def_property_readonly("columns", &LabObject::columns, "The trace's columns, in order.")
      .def_property_readonly("units", &LabObject::units, "Each trace column's SI unit ('' if none); an actuated joint's by its kind: tau_ in N·m on a hinge, N on a slide.")
      .def_property_readonly("dt", &LabObject::dt)
      .def_property_readonly("duration", &LabObject::duration)
      .def("set_gains", [](LabObject& lab, py::object gains, py::kwargs more) {
        // set_gains({"k_p": 400}), set_gains(k_p=400) or set_gains("gains.json") (a gains file).
        std::string path;
        if (!gains.is_none() && asPath(gains, path)) {
          if (more.size()) throw py::type_error("set_gains: a gains file or keyword gains, not both");
          lab.apply(gains, path);
          return;
        }
        py::dict g = gains.is_none() ? py::dict() : py::dict(gains);
        for (const auto& [k, v] : more) g[k] = v;
        py::dict sub;
        sub["gains"] = g;
        lab.apply(sub, kGainsSource);
      }, py::arg("gains") = py::none(), "Sets gains (dict, keywords or a gains file); bad input raises InputError.")
      .def("apply", [](LabObject& lab, py::object submission) {
        std::string path;
        lab.apply(submission, asPath(submission, path) ? path : kSubmissionSource);
      }, py::arg("submission"), "Applies a submission (dict or file): its gains and options.")
      .def("submission", [](const LabObject& lab) { return toPython(lab.submission()); },
           "The current gains and options as a submission dict (what dynlab.grade takes).")
      .def("run", &LabObject::run, py::arg("engine") = "both", py::arg("duration") = std::nullopt,
           py::arg("scenario") = "",
           "Runs the lab as `dynlab run` does: returns summary.json's fields and 'traces' "
           "(engine → column → NumPy array). Ctrl-C stops it (KeyboardInterrupt).")
      .def("screen", &LabObject::screen, "Poles and margins of the linearised loops at the current gains.")
      .def("frame", &LabObject::frame, py::arg("t"), py::arg("engine") = "hand", py::arg("width") = 640,
           py::arg("height") = 480, py::arg("overlay") = true,
           "The last run at time t as an RGB array (height, width, 3), drawn as `dynlab run --frames` draws it "
           "(with both engines run, the other one as a ghost). plt.imshow(lab.frame(1.0)) shows it.")
      .def("video", [](const LabObject& lab, py::object path, const std::string& engine, int width, int height) {
        std::string p;
        if (!asPath(path, p)) throw py::type_error("video: path must be a str or os.PathLike");
        return lab.video(p, engine, width, height);
      }, py::arg("path"), py::arg("engine") = "hand", py::arg("width") = 640, py::arg("height") = 480,
           "Writes the last run as an MP4 (H.264, 30 fps) at path, whole or not at all; returns its absolute path.")
      .def("grade", [](const LabObject& lab, double time_budget) {
        return grade(toPython(lab.submission()), lab.name(), lab.configFile(), time_budget, lab.student());
      }, py::arg("time_budget") = 300.0, "Grades the current gains (dynlab.grade of submission()).")
      .def("__repr__", [](const LabObject& lab) { return "<dynlab.Lab " + lab.name() + ">"; });

  m.def("grade", &grade, py::arg("submission"), py::arg("lab") = "", py::arg("config") = "", py::arg("time_budget") = 300.0,
        py::arg("student") = "",
        "Grades a submission (dict or file) as `dynlab grade` does (on STUDENT's plant when given); returns results.json "
        "as a dict.");
}

PYBIND11_MODULE(dynlab, m) { defineModule(m); }
