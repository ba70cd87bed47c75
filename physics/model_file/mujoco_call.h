// MuJoCo's error and warning handlers, kept away from the process: by default mju_error prints,
// writes MUJOCO_LOG.TXT into the working folder and exits, and mju_warning writes the same log. While
// a MujocoGuard lives, a warning is collected and an error jumps back to the guarded call
// (MUJOCO_CALL), which then throws one line. (MuJoCo's XML compiler installs its own handler while it
// compiles and reports through mj_loadXML's error buffer; this guard covers the rest.)
#pragma once
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <csetjmp>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "physics/model_file/model_file.h"
#include "physics/model_file/urdf_read.h"

namespace dyn::model_file::detail {

struct MujocoGuard {
  MujocoGuard();
  ~MujocoGuard();
  MujocoGuard(const MujocoGuard&) = delete;
  MujocoGuard& operator=(const MujocoGuard&) = delete;
  std::string warnings() const;  // collected since the guard was made, one line
  void (*error_)(const char*);
  void (*warning_)(const char*);
};

// The jump target of the innermost guarded call, and the error it carries.
std::jmp_buf*& jumpTarget();
std::string& lastError();

// One line: newlines and control characters become spaces, runs of spaces one.
std::string oneLine(const std::string& text);

// A model compiled by MuJoCo (LoadedModel::compiled): owned, read only once made.
struct Compiled {
  mjModel* m = nullptr;
  std::vector<std::string> notes;  // what the file writes that MuJoCo 2.2.2 reads as nothing (a URDF's <mimic>)
  Compiled() = default;
  ~Compiled();
  Compiled(const Compiled&) = delete;
  Compiled& operator=(const Compiled&) = delete;
};

// FILE compiled by MuJoCo from the checked files, in the fence (compile.cpp); MuJoCo's warnings into
// *warnings. Throws ModelFileError.
std::shared_ptr<const Compiled> compile(const std::string& path, std::string* warnings,
                                        const std::vector<std::string>& package_paths = {});

// The model's text and its includes (in vfs) within kMaxBodies, kMaxJoints, kMaxGeoms and
// kMaxEqualities, no <composite>, includes nested at most kMaxIncludeDepth (sizes.cpp).
void checkSizes(const std::string& path, const std::string& text, const mjVFS* vfs);

// The model file's bytes: a regular file of at most kMaxFileBytes, not blank, well-formed UTF-8
// (files.cpp). Throws ModelFileError.
std::string readChecked(const std::string& path);

// bytes as the virtual file `name` (MuJoCo keeps its last part); errors name `path`.
void putFile(mjVFS* vfs, const std::string& path, const std::string& name, const std::string& bytes);

// Where a name the model gives a file is looked for (package://NAME/…, file://…, plain names under the
// model's folder and its meshdir/texturedir/assetdir) and the folders it may be read from
// (packages.cpp).
class FileSearch {
 public:
  // folder: the model's folder, canonical; package_paths: --package-path folders (ROS_PACKAGE_PATH is read too).
  FileSearch(const std::filesystem::path& folder, const std::vector<std::string>& package_paths);
  // The paths name may be at, in order (none: a package not found); `looked` says where, for errors.
  std::vector<std::filesystem::path> candidates(const std::string& name, const std::vector<std::string>& dirs, std::string& looked);
  // real (canonical) lies inside the model's folder, its ROS package, a --package-path folder or a package found.
  bool allowed(const std::filesystem::path& real) const;
  std::string roots() const;  // those folders, for errors

 private:
  std::filesystem::path package(const std::string& name) const;
  std::filesystem::path folder_;
  std::vector<std::string> package_paths_, ros_;
  std::vector<std::filesystem::path> roots_;
};

// Every file the model's text names (includes, meshes, textures, height fields, skins; URDF's mesh
// filename), checked (a regular file inside the folders FileSearch allows, within kMaxAssetBytes,
// kMaxAssetFiles and kMaxAssetsBytes; an included .xml or .urdf as the model file is, and scanned in
// turn) and put into vfs under its name; a name with no such file gets a one-byte stand-in. Returns
// those names, each with where it was looked for ("'NAME' not found (looked in …)"). urdf: the model's
// facts when it is a URDF (read once by the caller: its discarded visuals are checked, not refused).
std::vector<std::string> addReferencedFiles(const std::string& path, const std::string& bytes, mjVFS* vfs,
                                            const std::vector<std::string>& package_paths = {}, const UrdfFacts* urdf = nullptr);

// Whether a model file's name ends in .urdf (any case): MuJoCo reads it as URDF.
bool isUrdfPath(const std::string& path);

// The model's geoms at qpos0 (after mj_kinematics) as drawing shapes on the tree bodies: body b moves
// with tree body link[b] (−1: the world), whose frame origin at qpos0 is origin[b] (drawing.cpp).
void readDrawing(const mjModel* m, const mjData* d, const std::vector<int>& link, const std::vector<Eigen::Vector3d>& origin,
                 Drawing& out);

// dynlab's own elements given beside the file (options.rolling, options.contacts) onto out's description,
// after its closures, and into out.contacts (elements.cpp). Body b as in readDrawing.
void addElements(const std::string& path, const mjModel* m, const mjData* d, const std::vector<int>& link,
                 const std::vector<Eigen::Vector3d>& origin, const LoadOptions& options, LoadedModel& out);

// A ball or free joint (ball_joints.cpp): refused in one line if it has a spring or (a ball) a limit;
// added after tree body `link` (frame origin `origin`, both updated to the joint's last body), with its
// Joint entries (one per rate) and coordinate names (one per qpos).
// (name, body: the joint's and its body's names as errors and columns show them.)
void checkBallJoint(const std::string& path, const mjModel* m, int j, const std::string& name, const std::string& body);
void addBallJoint(const mjModel* m, const mjData* d, int b, int j, const std::string& name, const std::string& body, int& link,
                  Eigen::Vector3d& origin, LoadedModel& out);

// Tendons and muscle actuators dynlab cannot hold, refused in one line (joint_elements.cpp).
void checkTendons(const std::string& path, const mjModel* m);

// Fixed tendon t's length as a linear form of the coordinates (joint_elements.cpp).
std::vector<TendonTerm> fixedTendonPath(const mjModel* m, int t);

// The fixed tendons with stiffness, damping or frictionloss into out.tendons, each noted (joint_elements.cpp).
void readTendons(const mjModel* m, LoadedModel& out);

// The file's joint limits and joint and fixed-tendon equalities onto out's description, after its
// closures, and into out.contacts (joint_elements.cpp).
void addJointElements(const std::string& path, const mjModel* m, const LoadOptions& options, LoadedModel& out);

// Geoms that may collide in MuJoCo, as one note (contacts.cpp); nothing when the file disables contact.
void noteContacts(const mjModel* m, std::vector<std::string>& notes);

// The file's actuators into out.actuators (refused in one line unless they fit Actuator's law), then
// the run's start into out.start_q, start_v and ctrl: the keyframe named `key` (checked against the
// loops) or q0 at rest (controls.cpp).
void readActuators(const std::string& path, const mjModel* m, LoadedModel& out);
void readStart(const std::string& path, const mjModel* m, const std::string& key, LoadedModel& out);

}  // namespace dyn::model_file::detail

// Runs the statement; a MuJoCo error inside it throws ModelFileError("<file>: MuJoCo: <message>").
// (setjmp needs the caller's frame: a macro, not a function.)
#define MUJOCO_CALL(file, statement)                                                              \
  do {                                                                                           \
    std::jmp_buf jump_;                                                                          \
    std::jmp_buf* const outer_ = ::dyn::model_file::detail::jumpTarget();                        \
    ::dyn::model_file::detail::jumpTarget() = &jump_;                                            \
    if (setjmp(jump_) == 0) {                                                                    \
      statement;                                                                                 \
      ::dyn::model_file::detail::jumpTarget() = outer_;                                          \
    } else {                                                                                     \
      ::dyn::model_file::detail::jumpTarget() = outer_;                                          \
      throw ::dyn::model_file::ModelFileError(std::string(file) + ": MuJoCo: " +                 \
                                              ::dyn::model_file::detail::lastError());           \
    }                                                                                            \
  } while (0)
