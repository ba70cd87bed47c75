// A lab without C++: a folder labs/<name>/ with <name>.json, handout.md, examples/ and a model file,
// and no .cpp or .h, is served by this one generic lab class, registered once per such folder found
// (registerDataLabs; no registration line per lab). Its JSON says, besides the blocks every lab has
// (simulation, gains, rubric, metric_docs, figures, submission_options):
//   "model_file": "fivebar.xml"          MJCF or URDF beside the JSON (physics/model_file)
//   "actuated": ["left_crank", ...]      the joints the controller drives; the others are passive
//   "torque_limit": [..]                 N·m per actuated joint (N on a slide: its actuator pushes)
//   "tool": {"closure": "pin_C"} | {"body": "left_link", "at": [x, y, z]}   the task point, "axes":
//                                        ["x", "z"]; "at" is in metres, world coordinates at the model
//                                        file's own pose (its qpos0: every joint at 0 in a URDF), not at
//                                        "initial"'s pose, and moves with the body from there; none: no
//                                        task and no trajectory (a passive model: `dynlab figure FILE`)
//   "initial": {"actuated_deg": [..]} | {"actuated": [..]}   the actuators' start, in degrees (hinges
//                                        only: a slide's is refused) or in each joint's own unit (rad,
//                                        m); the passive joints are assembled
//   "trajectory": {"segments": [...]}    the task path from the tool's start (labs/generic/task_path.h),
//                                        refused when read if a point is out of reach or singular (reach.h);
//                                        with "space": "joint" a joint path of the actuated joints, fed
//                                        to the joint laws without inverse kinematics (tool optional)
//   "plant": {"payloads": [{"body", "at", "mass"}]}   point masses (kg) the plant carries and the
//                                        controller's model does not (scenarios change them); "at" as
//                                        the tool's: world metres at the file's pose, fixed to the body
//   "environment": {"force": {"value": [Fx, Fy, Fz], "start", "rise", "hold"}}   a push on the tool
//                                        (N, world axes; physics/forces.h's profile), on the plant only:
//                                        both engines apply J_toolᵀ F inside each step; trace push_x/y/z
//   "controller": {"kind", "control_period", "delay_steps", "noise": {"angle", "rate", "force", "seed"},
//                  (the encoders' σ per joint in its own unit: "angle" rad on a hinge, m on a slide;
//                  "rate" rad/s or m/s)
//                  "constant", "joint_scale", "posture_omega"}   a law of labs/controllers, gains from
//                                        "gains"; the impedance laws' force sensor reads the push on the
//                                        tool (in the task axes) as late as the encoders, noise "force" N
//   "target": {"k", "m", "zeta"}         the exercise's target impedance M ξ'' + D ξ' + K ξ = F_push per
//                                        task axis (ξ = x − x_d, D = 2ζ√(KM)): trace target_<axis> = x_d + ξ
//                                        (RK4, four substeps a row) and dev_<axis> = tool − target
//   "metrics": {...}                     labs/generic/metric_spec.h
//   "passive_tolerance": 1e-6            the passive energy check's |E − E0|/|E0|
// Trace columns: t, q_<joint> (every coordinate), v_<joint>, tau_<actuated>, tau_sat, tool_<axis>,
// ref_<axis>, e_<axis> (a joint path: ref_<actuated>, e_<actuated>), push_x/y/z (with a push),
// target_<axis>, dev_<axis> (with a target), energy, work, constraint_residual,
// and f_<closure>_<row> (force, world axes, of each kept closure row: rows wx wy wz are moments, x y z
// forces), then load_<joint>_x|y|z for each passive joint: the force its bearing carries (its parent on
// it, world axes; jointLoads).
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "labs/controllers/controller.h"
#include "labs/generic/metric_spec.h"
#include "labs/generic/task_path.h"
#include "labs/model_scene.h"
#include "labs/settings_lab.h"
#include "physics/forces.h"
#include "physics/model_file/model_file.h"

namespace dyn::generic {

struct DataSettings {
  std::string name, folder, title;
  std::shared_ptr<const model_file::LoadedModel> plant;  // with the payloads
  MechanismModel<Spatial> model;                         // the controller's: without them
  std::vector<int> actuated;
  std::vector<std::string> actuated_names, axis_names;
  controllers::TaskPoint tool;
  bool tool_on_body = false;  // the tool given as {"body", "at"} (drawn as a stick), not a closure's point
  VecN q0;  // assembled start
  std::shared_ptr<const TaskPath> path;
  std::optional<PushForce<Spatial>> push;  // the environment's push on the tool (the plant has it too)
  struct Target {
    double k = 0, m = 1, zeta = 0;  // N/m, kg, 1 (k = 0: no target)
  } target;
  controllers::Spec controller;
  StepOptions step;
  double duration = 1, passive_tolerance = 1e-6;
  std::map<std::string, MetricSpec> metrics;
  std::vector<std::string> columns;
  std::vector<int> passive;  // the tree joints not actuated (their loads are traced)
};

// Parses a data lab's config (its folder: where the model file is; options: loops given beside it).
DataSettings parseDataSettings(const JsonView& config, const std::string& name, const std::string& folder,
                               const model_file::LoadOptions& options = {});

class DataLab final : public SettingsLab<DataSettings> {
 public:
  // Its tables (settings_lab.h): the columns parsed, the agreement's units (max_dq in the joints' own),
  // the passive check (without the push, which does work by design: E itself must then stay put).
  explicit DataLab(DataSettings s);
  // Each column's unit from its joint's kind (rad or m, N·m or N) and the blocks the JSON declares.
  std::string unit(const std::string& column) const override;
  // The run: the model file's mechanism assembled, a law of labs/controllers, the push (data_lab.cpp).
  std::unique_ptr<Simulation> simulate(Engine engine) const override;
  // Its own model file, as MuJoCo compiled it at load (the plant's payloads are the hand engine's only).
  MujocoTwin mujocoTwin() const override;
  // The grade: the JSON's metrics (metric_spec.h), the engines' agreement.
  json metrics(const Trace& trace) const override;
  json differences(const Trace& hand, const Trace& bullet, std::size_t rows) const override;
  // The picture: the model file's bodies, the tool, its path and the push (model_scene.h).
  void scene(const Trace& trace, std::size_t row, const Trace* ghost, Scene& out) const override;
  void overlay(const Trace& trace, std::size_t row, Overlay& out) const override;

 private:
  ModelPicture picture_;
  std::unique_ptr<ConstrainedMechanism<Spatial>> kinematics_;  // the plant's, for the tool's place in a picture
  mutable const double* bounds_of_ = nullptr;  // the trace whose run bounds are cached
  mutable std::size_t bounds_rows_ = 0;
  mutable Eigen::AlignedBox3d bounds_;
  mutable std::vector<Eigen::Vector3d> points_;  // the run's shapes' points (runPoints; none for rods or a planar plant)
  mutable double arrow_ = 0;  // m: the push's arrow at the push's full value (0: none drawn)
  mutable double tool_ball_ = 0;  // m: the radius of the tool's ball (a tool on a body)
};

// True if labs/<name>/ is a data lab folder: <name>.json there, and no .cpp or .h.
bool isDataLabFolder(const std::string& folder, const std::string& name);
// Registers the data lab in `folder` (named by the folder); false with a sentence in *why if it cannot.
// labs_folder: the folder of lab folders outside the tree it is in (LabEntry::labs_folder; empty: the tree).
bool registerDataLab(const std::string& folder, std::string* why = nullptr, const std::string& labs_folder = "");
// Registers every data lab folder under `labs_root`; returns how many.
int registerDataLabs(const std::string& labs_root);

}  // namespace dyn::generic
