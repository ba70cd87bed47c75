// dynlab.Lab: one lab with its config and the gains set so far. Each object owns its config and
// its built lab; nothing is shared between two Lab objects but the registry (read only).
// Safe from several Python threads: what changes (the config, the last run) changes only with the
// GIL held; what runs without it (a run, a frame, a video) works on its own copy: run() on the lab
// it built, frame() and video() on the last run they took (a run() meanwhile replaces the object's
// last run, not theirs); drawing is one at a time in the process (Dear ImGui has one current context).
#pragma once
#include <memory>
#include <optional>
#include <string>

#include <pybind11/numpy.h>

#include "app/python/convert.h"
#include "labs/run.h"
#include "labs/trace.h"

namespace dyn::python {

class LabObject {
 public:
  // On student's plant (labs/variants.h; "" the nominal one).
  LabObject(const std::string& name, const std::string& config_file, const std::string& student = "");
  const std::string& student() const { return plant_.student; }

  std::string name() const { return loaded_.entry->name; }
  const std::string& configFile() const { return loaded_.config_file; }
  py::dict gains() const;     // name → value
  py::dict gainInfo() const;  // name → {value, min, max, unit, doc}
  py::list columns() const;
  py::dict units() const;
  double dt() const { return loaded_.lab->dt(); }
  double duration() const { return loaded_.lab->duration(); }

  // A submission's gains (and options) applied to the current config, as `dynlab run --gains F`
  // does; a path is read as that file. Throws InputError (nothing changed) on bad input.
  void apply(py::handle submission, const std::string& source);
  // {"lab", "gains": {every gain}, <each option>}: what grading the current gains takes.
  json submission() const;

  // Both engines (or one) to the end, as `dynlab run`: the summary.json numbers and the traces.
  py::dict run(const std::string& engine, std::optional<double> duration, const std::string& scenario) const;
  // Poles and margins of the lab's linearised loops at the current gains (the grader's screening).
  py::dict screen() const;
  // The last run drawn at time t (the lab's scene; with both engines the other one as a ghost), as
  // an RGB array (height, width, 3) of uint8, offscreen (OSMesa: no display needed).
  py::array frame(double t, const std::string& engine, int width, int height, bool overlay) const;
  // The last run as an MP4 (H.264, 30 fps) at `path`, written whole or not at all; returns the path.
  std::string video(const std::string& path, const std::string& engine, int width, int height) const;

 private:
  // What frame() and video() draw: the last run's lab (its scenario and duration) and traces.
  struct LastRun {
    std::unique_ptr<Lab> lab;
    std::optional<Trace> hand, bullet;
  };
  // The last run, shared with the caller (which keeps it alive while it draws without the GIL).
  std::shared_ptr<const LastRun> lastRun() const;
  // The trace of `run` shown for `engine` ("hand" or "bullet") and the other engine's as its ghost (or null).
  static std::pair<const Trace*, const Trace*> shown(const LastRun& run, const std::string& engine);

  PlantChoice plant_;
  LoadedLab loaded_;
  mutable std::shared_ptr<const LastRun> last_;  // replaced (with the GIL held) by each run()
};

// Runs `body` with the GIL released, asking Python for pending signals every 1024 steps through
// the stop request it is given; a KeyboardInterrupt (or any exception a signal handler raised)
// is rethrown once body has returned.
class Interruptible {
 public:
  bool operator()();  // the stop request: true once a signal handler raised
  void rethrow();     // with the GIL held

 private:
  std::optional<py::error_already_set> pending_;
};

// Defines the module's functions and classes in m (module.cpp).
void defineModule(py::module_& m);

}  // namespace dyn::python
