// A model file compiled by MuJoCo, once, in the fence (mujoco_call.h's compile): the file and every
// file it names read and checked here (files.cpp) into MuJoCo's virtual file system; then, in a
// child process under time and memory limits (fence.h), its size counted against the limits
// (sizes.cpp), mj_loadXML run on those virtual files alone, the data it needs bounded, and the
// compiled model sent back in MuJoCo's binary form (mj_saveModel) to be read here (mj_loadModel).
// A parser crash, hang or exhaustion ends only the child; what the caller keeps is the compiled
// model, which the cross-check and the bench start from (no second parse, no second read).
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>

#include "physics/model_file/fence.h"
#include "physics/model_file/mjcf3.h"
#include "physics/model_file/mujoco_call.h"
#include "physics/model_file/urdf_read.h"

namespace dyn::model_file::detail {
namespace {

// A virtual file system that cleans up after itself.
struct Vfs {
  std::unique_ptr<mjVFS> v = std::make_unique<mjVFS>();
  Vfs() { mj_defaultVFS(v.get()); }
  ~Vfs() { mj_deleteVFS(v.get()); }
  Vfs(const Vfs&) = delete;
  Vfs& operator=(const Vfs&) = delete;
  mjVFS* get() { return v.get(); }
};

// MuJoCo's allocations in the child, aligned as its own are (64 bytes: mjModel's layout depends on
// it): a failed one ends the child as out of memory (MuJoCo would report it as the model's error).
void* allocate(std::size_t size) {
  void* p = std::aligned_alloc(64, (size + 63) & ~std::size_t(63));
  if (!p && size > 0) fenceOutOfMemory();
  return p;
}

std::string mib(std::size_t bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }

// In the child: the text's sizes, MuJoCo's parse of the virtual files, the data it needs; the reply
// is the warnings' length (4 bytes), the warnings, then the compiled model.
std::string parse(const std::string& path, const std::string& bytes, mjVFS* vfs, const std::vector<std::string>& missing) {
  mju_user_malloc = allocate;
  mju_user_free = std::free;
  checkSizes(path, bytes, vfs);
  char error[1024] = "";
  MujocoGuard guard;
  Mjcf3 translation;
  auto load = [&] {
    mjModel* m = nullptr;
    MUJOCO_CALL(path, m = mj_loadXML(path.c_str(), vfs, error, sizeof error));
    if (m) return m;
    // A file the model names and dynlab did not find is the likely cause: named first, with where it was looked for.
    std::string why = path + ": ";
    for (std::size_t i = 0; i < missing.size() && i < 3; ++i) why += (i ? "; " : "file ") + missing[i];
    if (missing.size() > 3) why += "; and " + std::to_string(missing.size() - 3) + " more";
    if (!missing.empty()) why += "; then ";
    throw ModelFileError(why + "MuJoCo's parser: " + translation.ownLines(oneLine(error[0] ? error : "no model")));
  };
  // MuJoCo 3 syntax into 2.2.2's, in the virtual files (mjcf3.cpp), then the model MuJoCo compiles.
  translateMjcf3(path, bytes, vfs, load, translation);
  const std::string& notes = translation.notes;
  mjModel* m = load();
  mjData* d = nullptr;
  MUJOCO_CALL(path, d = mj_makeData(m));
  if (!d) throw ModelFileError(path + ": MuJoCo could not make its data");
  const std::size_t data = std::size_t(d->nbuffer) + std::size_t(d->nstack) * sizeof(mjtNum);
  mj_deleteData(d);
  if (data > kMaxDataBytes)
    throw ModelFileError(path + ": MuJoCo's data for this model takes " + mib(data) + ", more than " + mib(kMaxDataBytes) +
                         " (<size> nstack, njmax, nconmax: leave them to MuJoCo)");
  const int size = mj_sizeModel(m);
  const std::string said = oneLine(std::string(error) + " " + guard.warnings());
  const std::string warnings = notes.empty() ? said : said.empty() ? notes : notes + "; " + said;
  const auto n = std::uint32_t(warnings.size());
  std::string reply(reinterpret_cast<const char*>(&n), 4);
  reply += warnings;
  const std::size_t at = reply.size();
  reply.resize(at + std::size_t(size));
  mj_saveModel(m, nullptr, reply.data() + at, size);
  mj_deleteModel(m);
  return reply;
}

}  // namespace

Compiled::~Compiled() {
  if (m) mj_deleteModel(m);
}

std::shared_ptr<const Compiled> compile(const std::string& path, std::string* warnings, const std::vector<std::string>& package_paths) {
  const std::string bytes = readChecked(path);
  const std::string name = std::filesystem::path(path).filename().string();
  if (name.size() >= mjMAXVFSNAME) throw ModelFileError(path + ": file name longer than MuJoCo's " + std::to_string(mjMAXVFSNAME - 1) + " characters");
  Vfs vfs;
  // The virtual file keeps the name alone; loading it by its path keeps the file's folder as the
  // model's, where MuJoCo looks for includes and meshes.
  putFile(vfs.get(), path, path, bytes);
  // A URDF's elements read once (urdf_read.cpp): its discarded visuals for the file scan, its <mimic>s below.
  const std::optional<UrdfFacts> urdf = isUrdfPath(path) ? std::optional<UrdfFacts>(readUrdfFacts(bytes)) : std::nullopt;
  const std::vector<std::string> missing = addReferencedFiles(path, bytes, vfs.get(), package_paths, urdf ? &*urdf : nullptr);
  FenceLimits limits;
  limits.seconds = kParseSeconds;
  limits.memory_bytes = kParseMemoryBytes;
  const std::string reply = fenced(path, "MuJoCo's parser", limits, [&] { return parse(path, bytes, vfs.get(), missing); });
  // The compiled model back from its binary form, through a virtual file of its own.
  std::uint32_t n = 0;
  if (reply.size() >= 4) std::memcpy(&n, reply.data(), 4);
  if (reply.size() < 4 + std::size_t(n)) throw ModelFileError(path + ": MuJoCo's parser answered with a cut-off model");
  if (warnings) *warnings = reply.substr(4, n);
  Vfs binary;
  putFile(binary.get(), path, "model.mjb", reply.substr(4 + std::size_t(n)));
  auto out = std::make_shared<Compiled>();
  MujocoGuard guard;
  MUJOCO_CALL(path, out->m = mj_loadModel("model.mjb", binary.get()));
  if (!out->m) throw ModelFileError(path + ": MuJoCo could not read back the model it compiled");
  // A URDF's <mimic> (a finger following another, as Bullet's and ROS's Panda write it): MuJoCo 2.2.2's
  // URDF reader drops it, so the joint moves on its own; said, with the way to hold it.
  // Its elements (urdf_read.cpp), not its text: a <mimic> commented out is none.
  if (const std::size_t mimics = urdf ? urdf->mimics : 0; mimics > 0)
    out->notes.push_back(std::to_string(mimics) + " URDF <mimic> element(s) not held (MuJoCo 2.2.2's URDF reader ignores them: each such joint moves "
                         "on its own); to couple them, write the robot as MJCF with <equality><joint joint1 joint2 polycoef=\"0 1 0 0 0\"/>");
  return out;
}

}  // namespace dyn::model_file::detail
