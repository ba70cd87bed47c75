// Labs outside the dynlab tree (--labs DIR, DYNLAB_LABS): see lab_folders.h.
#include "labs/generic/lab_folders.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <regex>

#include "labs/config.h"
#include "labs/generic/data_lab.h"
#include "labs/lab.h"

namespace dyn::generic {
namespace {

namespace fs = std::filesystem;

// The folders registered so far: absolute as given, and canonical (to use a folder once).
struct InUse {
  std::vector<std::string> absolute;
  std::vector<fs::path> canonical;
};
InUse& inUse() {
  static InUse folders;
  return folders;
}
std::mutex& inUseMutex() {
  static std::mutex m;
  return m;
}

[[noreturn]] void refuse(const LabsFolder& f, const std::string& what) {
  throw InputError(f.source, f.origin, what);
}

// Where a lab of that name already is, for the clash's message.
std::string whereIs(const LabEntry& e) {
  const std::string folder = labFolder(e.name);
  return e.labs_folder.empty() ? "the dynlab tree's lab " + e.name + " (" + folder + ")" : "the lab " + e.name + " in " + e.labs_folder;
}

// The lab folders of one folder of lab folders, sorted: each a subfolder holding <name>.json.
std::vector<fs::path> labFoldersIn(const fs::path& dir) {
  std::vector<fs::path> found;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, fs::directory_options::skip_permission_denied, ec)) {
    const std::string name = e.path().filename().string();
    if (!name.empty() && name[0] != '.' && e.is_directory(ec) && isDataLabFolder(e.path().string(), name)) found.push_back(e.path());
  }
  std::sort(found.begin(), found.end());
  return found;
}

// Registers one folder's labs after checking every name (none registered when one is refused).
void useOne(const LabsFolder& f) {
  std::error_code ec;
  if (f.path.find('\0') != std::string::npos) refuse(f, "expected a folder path without a NUL byte");
  const fs::path given(f.path);
  if (!fs::is_directory(given, ec)) refuse(f, "expected an existing folder of lab folders, got \"" + f.path + "\"");
  const fs::path absolute = fs::absolute(given, ec).lexically_normal();
  const fs::path canonical = fs::canonical(given, ec);
  if (ec) refuse(f, "cannot read the folder \"" + f.path + "\" (" + ec.message() + ")");
  if (absolute.string().find(':') != std::string::npos)
    refuse(f, "expected a folder path without ':' (DYNLAB_LABS separates folders with it), got \"" + absolute.string() + "\"");
  // The tree's own labs/ given again (new-lab's old habit) is the tree: its labs are there already.
  if (canonical == fs::weakly_canonical(labsRoot(), ec)) return;
  InUse& used = inUse();
  if (std::find(used.canonical.begin(), used.canonical.end(), canonical) != used.canonical.end()) return;
  std::string dir = absolute.string();
  if (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  const std::vector<fs::path> labs = labFoldersIn(absolute);
  static const std::regex lab_name("[a-z][a-z0-9_]{0,39}");
  for (std::size_t i = 0; i < labs.size(); ++i) {
    const std::string name = labs[i].filename().string(), folder = labs[i].string();
    if (!std::regex_match(name, lab_name))
      refuse(f, folder + ": expected a lab folder named with lowercase letters, digits and _, starting with a letter (at most 40)");
    if (const LabEntry* e = findLab(name))
      refuse(f, folder + ": expected a lab name no other lab has; " + name + " is " + whereIs(*e) + " (rename the folder, its " +
                    name + ".json and its \"lab\")");
  }
  for (const fs::path& lab : labs) {
    std::string why;
    if (!registerDataLab(lab.string(), &why, dir)) refuse(f, why);
  }
  used.absolute.push_back(dir);
  used.canonical.push_back(canonical);
}

}  // namespace

std::vector<LabsFolder> labsFoldersFromEnvironment() {
  std::vector<LabsFolder> out;
  const char* env = std::getenv("DYNLAB_LABS");
  if (!env) return out;
  const std::string list = env;
  for (std::size_t at = 0; at <= list.size();) {
    const std::size_t end = std::min(list.find(':', at), list.size());
    if (end > at) out.push_back({list.substr(at, end - at), "DYNLAB_LABS", "<environment>"});
    at = end + 1;
  }
  return out;
}

void useLabsFolders(const std::vector<LabsFolder>& folders) {
  const std::lock_guard<std::mutex> lock(inUseMutex());
  for (const LabsFolder& f : folders) useOne(f);
}

std::vector<std::string> labsFoldersInUse() {
  const std::lock_guard<std::mutex> lock(inUseMutex());
  return inUse().absolute;
}

}  // namespace dyn::generic
