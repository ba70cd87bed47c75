// Lab: the interface every lab implements, and the registry they add themselves to
// (like Box2D's samples): a new lab is a new folder under labs/<name>/ (its JSON, controller,
// metrics, scene, examples/, README) with one
//   DYNLAB_REGISTER_LAB(name, summary, factory)
// and no change anywhere else. app/, grading/ and render/ know labs only through this interface.
// The contract every lab keeps (tests/labs/every_lab_test.cpp checks it for each registered lab):
//   * its JSON has the shared "simulation" block and declared "gains" (labs/settings.h), and may
//     declare "submission_options" (labs/submission.h);
//   * it accepts passivePatch() ({"controller": {"kind": "none"}}: τ = 0), and its trace has
//     columns "t" and "energy";
//   * linearise() reports the same loops whatever the submission options (a loop an option does
//     not close is reported with no feedback), so every rubric metric exists for every option.
#pragma once
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "labs/config.h"
#include "labs/mujoco_twin.h"
#include "labs/settings.h"
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
  // Non-empty once the run has gone bad (non-finite state, failed projection): a plain sentence,
  // which stoppedSentence() completes. A lab's own watchdog (a grasp that slipped) writes the whole
  // sentence itself, starting "stopped: " and naming the time.
  virtual std::string failure() const { return {}; }
  // The engine alone, for `dynlab bench`: advance the state one more step under the torque τ (no
  // controller, no trace row; it uses up one step of the run). The bench replays the torques another
  // run of the same lab applied (appliedTorque after each of its step()s), so that this run takes the
  // lab's own path with nothing timed but the engine. False once the run is over, or if the lab does
  // not offer it.
  virtual bool advanceEngine(const VecN& tau) {
    (void)tau;
    return false;
  }
  // The torque the last step() applied over its step: empty before the first, after the row at the
  // run's end (no step follows it), and where advanceEngine is not offered.
  virtual VecN appliedTorque() const { return {}; }
  // The state (q, v) the next step starts from; false where advanceEngine is not offered.
  virtual bool engineState(VecN& q, VecN& v) const {
    (void)q, (void)v;
    return false;
  }
  // The engine in one line, when it can say more than its name (Bullet: the multibody it built from the
  // description, where it cut the loops, the solver's effort); empty otherwise.
  virtual std::string describeEngine() const { return {}; }
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
  // Where the engines disagree (the summary's "agreement"): its top-level numbers are the
  // measures of disagreement, printed with agreementUnit(key) ("rad", "m"; empty: none or a count).
  virtual json agreement(const Trace& hand, const Trace& bullet) const = 0;
  virtual std::string agreementUnit(const std::string& key) const {
    (void)key;
    return {};
  }
  // Engine::Bullet in one line, e.g. "Bullet 3.24 btMultiBody, PGS 30 iterations" (dynlab bench).
  virtual std::string referenceEngine() const { return "Bullet"; }

  // The passive check: with passivePatch() applied, the hand engine keeps the "energy" column
  // within |E − E0| ≤ tolerance·|E0| (absolute when E0 = 0) over `duration` s (0: the whole run).
  // `conservative`: a merge patch applied with passivePatch() for this check, taking out what
  // dissipates by design (a lab's joint friction), so that E itself must stay put.
  struct PassiveEnergy {
    double tolerance = 1e-6;
    double duration = 0;
    json conservative = json::object();
  };
  virtual PassiveEnergy passiveEnergy() const { return {}; }

  // What to draw at a trace row; ghost (the other engine) drawn translucent when given.
  virtual void scene(const Trace& trace, std::size_t row, const Trace* ghost, Scene& out) const = 0;
  virtual void overlay(const Trace& trace, std::size_t row, Overlay& out) const = 0;

  // The controller's feedback loops linearised at the start (the grader screens gains on them
  // before simulating: poles, delay margin). The same loops for every submission option and gain:
  // a loop without feedback (open loop, zero gains) has a zero numerator and is reported as such.
  virtual std::vector<LinearLoop> linearise() const { return {}; }

  // The lab's mechanism written for MuJoCo (labs/mujoco_twin.h): dynlab bench times MuJoCo's step on it
  // beside the hand engine's and Bullet's. Empty (no file): the lab has none.
  virtual MujocoTwin mujocoTwin() const { return {}; }
};

// The part of every lab's agreement() that says how well each engine kept its own books: the energy
// drift and constraint residual of each run's metrics (keys "energy_drift", "max_constraint_residual").
inline json engineHealth(const json& hand_metrics, const json& bullet_metrics) {
  auto health = [](const json& m) {
    return json{{"energy_drift", m["energy_drift"]}, {"max_constraint_residual", m["max_constraint_residual"]}};
  };
  return {{"hand", health(hand_metrics)}, {"bullet", health(bullet_metrics)}};
}

// A unit from a lab's table (unit(), agreementUnit()): empty when the key is not in it.
inline std::string unitIn(const std::map<std::string, std::string>& units, const std::string& key) {
  const auto it = units.find(key);
  return it == units.end() ? std::string() : it->second;
}

// What a run's failure() says in reports: a lab's own "stopped: ..." sentence as it is, anything else
// as "unstable: <failure> at t = <t> s".
std::string stoppedSentence(const std::string& failure, double t);

// Builds a lab from its config (already merged with gains); throws InputError on bad input.
using LabFactory = std::function<std::unique_ptr<Lab>(const JsonView& config)>;

struct LabEntry {
  std::string name;
  std::string summary;
  LabFactory create;
  std::string folder;       // the lab's folder (empty: labsRoot()/name, a C++ lab's)
  std::string labs_folder;  // the folder of lab folders outside the tree it came from (--labs DIR,
                            // DYNLAB_LABS; labs/generic/lab_folders.h); empty: the dynlab tree
};

// Sorted by name. A list: an entry stays where it is while labs are added (a folder of labs given to
// Python's dynlab.Lab(..., labs=) after another Lab holds its entry).
std::list<LabEntry>& labRegistry();
const LabEntry* findLab(const std::string& name);
// Adds a lab (at static initialisation, or at run time from a test); false, and nothing added, if
// the name is taken.
bool registerLab(LabEntry entry);
// Removes a lab registered at run time (a test's scratch lab); false if there is none of that name.
bool unregisterLab(const std::string& name);
// The lab's folder: where it was registered from (a data lab, in the tree or outside it), else
// labsRoot()/<name>.
std::string labFolder(const std::string& name);
// The lab's default config: <labFolder(name)>/<name>.json.
std::string defaultConfigPath(const std::string& name);
// The dynlab tree's folder of lab folders: the source tree's labs/. DYNLAB_HOME=DIR replaces the tree
// with DIR (DIR/labs, and DIR for model files a lab names from the tree): a hook for tests that need
// a tree lab changed. Labs outside the tree are added beside it, not instead (lab_folders.h).
std::string labsRoot();

#define DYNLAB_REGISTER_LAB(id, summary, factory) \
  static const bool dynlab_registered_##id = ::dyn::registerLab({#id, summary, factory, {}, {}})

}  // namespace dyn
