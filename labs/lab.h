// Lab: the interface every lab implements, and the registry they add themselves to
// (like Box2D's samples): a new lab is a new folder under labs/ with one
//   DYNLAB_REGISTER_LAB(name, summary, factory)
// and no change anywhere else.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "labs/config.h"
#include "physics/linear.h"
#include "labs/scene.h"
#include "labs/trace.h"

namespace dyn {

enum class Engine { Hand, Bullet };
inline const char* name(Engine e) { return e == Engine::Hand ? "hand" : "bullet"; }

// One run of one engine, advanced a fixed step at a time.
class Simulation {
 public:
  virtual ~Simulation() = default;
  // Computes the control, fills the trace row for the current time, advances one step.
  // Returns false (and fills nothing) once the run's duration is reached.
  virtual bool step(std::vector<double>& row) = 0;
  // Non-empty once the run has gone bad (non-finite state, failed projection): a plain sentence.
  virtual std::string failure() const { return {}; }
  // The engine alone, for `dynlab bench`: advance the state one more step with the control of the
  // last step() held (no controller, no trace row; it uses up one step of the run). False once the
  // run is over, or if the lab does not offer it.
  virtual bool advanceEngine() { return false; }
};

class Lab {
 public:
  virtual ~Lab() = default;
  virtual std::vector<std::string> columns() const = 0;
  // The SI unit of a trace column ("N", "rad", "N·m"; empty: unknown or dimensionless), for
  // summaries, plot labels and panels.
  virtual std::string unit(const std::string& column) const {
    (void)column;
    return {};
  }
  virtual double dt() const = 0;
  virtual double duration() const = 0;
  virtual std::unique_ptr<Simulation> simulate(Engine engine) const = 0;

  // Lab metrics of a run (tracking error, force error, energy drift, constraint residual ...).
  virtual json metrics(const Trace& trace) const = 0;
  // Where the engines disagree (the summary's "agreement").
  virtual json agreement(const Trace& hand, const Trace& bullet) const = 0;

  // What to draw at a trace row; ghost (the other engine) drawn translucent when given.
  virtual void scene(const Trace& trace, std::size_t row, const Trace* ghost, Scene& out) const = 0;
  virtual void overlay(const Trace& trace, std::size_t row, Overlay& out) const = 0;

  // The controller's feedback loops linearised at the start (the grader screens gains on them
  // before simulating: poles, delay margin). Empty when the lab has no feedback.
  virtual std::vector<LinearLoop> linearise() const { return {}; }
};

// Builds a lab from its config (already merged with gains); throws InputError on bad input.
using LabFactory = std::function<std::unique_ptr<Lab>(const JsonView& config)>;

struct LabEntry {
  std::string name;
  std::string summary;
  LabFactory create;
};

std::vector<LabEntry>& labRegistry();
const LabEntry* findLab(const std::string& name);
bool registerLab(LabEntry entry);
// The lab's default config: labs/<name>/<name>.json in the source tree, or $DYNLAB_HOME/labs/...
std::string defaultConfigPath(const std::string& name);

#define DYNLAB_REGISTER_LAB(id, summary, factory) \
  static const bool dynlab_registered_##id = ::dyn::registerLab({#id, summary, factory})

}  // namespace dyn
