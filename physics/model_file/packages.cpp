// Where a file a model names is looked for, and which folders it may be read from (mujoco_call.h's
// FileSearch), as users lay robots out:
//   plain names      under the model's folder and each meshdir/texturedir/assetdir, as written or by
//                    their last part (MuJoCo's URDF reader keeps the last part alone)
//   file://PATH      PATH, as a plain name
//   package://NAME/REST  REST inside the package folder NAME, found in each --package-path DIR (DIR/NAME,
//                    or DIR itself when it is named NAME), then in the folders above the model file (the
//                    folder itself when named NAME, or a folder NAME beside one of them, down to two levels
//                    below the root: never /dev or /etc), then in each
//                    ROS_PACKAGE_PATH folder as in --package-path
// What is found is read only from inside the model's folder, the ROS package it sits in (the nearest
// folder above holding a package.xml), a --package-path folder, or a package folder found for a name.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "physics/model_file/mujoco_call.h"

namespace dyn::model_file::detail {
namespace {

namespace fs = std::filesystem;

bool isDir(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}

bool present(const fs::path& p) {
  std::error_code ec;
  return fs::exists(fs::symlink_status(p, ec));
}

// The canonical form of p, or p when it cannot be resolved.
fs::path canonicalOr(const fs::path& p) {
  std::error_code ec;
  fs::path c = fs::canonical(p, ec);
  return ec ? p : c;
}

bool inside(const fs::path& folder, const fs::path& p) {
  const auto [f, q] = std::mismatch(folder.begin(), folder.end(), p.begin(), p.end());
  return f == folder.end();
}

// A package folder NAME in (or as) dir, or empty.
fs::path packageIn(const fs::path& dir, const std::string& name) {
  if (dir.filename() == name && isDir(dir)) return dir;
  if (isDir(dir / name)) return dir / name;
  return {};
}

std::vector<std::string> rosPackagePath() {
  std::vector<std::string> out;
  const char* env = std::getenv("ROS_PACKAGE_PATH");
  const std::string s = env ? env : "";
  for (std::size_t b = 0; b <= s.size();) {
    const std::size_t e = std::min(s.find(':', b), s.size());
    if (e > b) out.push_back(s.substr(b, e - b));
    b = e + 1;
  }
  return out;
}

std::string listed(const std::vector<std::string>& dirs) {
  std::string out;
  for (const std::string& d : dirs) out += (out.empty() ? "" : ", ") + oneLine(d);
  return out;
}

}  // namespace

FileSearch::FileSearch(const fs::path& folder, const std::vector<std::string>& package_paths)
    : folder_(folder), package_paths_(package_paths), ros_(rosPackagePath()) {
  roots_.push_back(folder);
  // The ROS package the model sits in: its meshes are often beside the model's folder (../meshes).
  for (fs::path a = folder; !a.empty(); a = a.parent_path()) {
    if (present(a / "package.xml")) {
      roots_.push_back(a);
      break;
    }
    if (a == a.root_path()) break;
  }
  for (const std::string& d : package_paths_)
    if (isDir(d)) roots_.push_back(canonicalOr(d));
}

fs::path FileSearch::package(const std::string& name) const {
  if (name.empty() || name == "." || name == "..") return {};
  for (const std::string& d : package_paths_)
    if (fs::path p = packageIn(d, name); !p.empty()) return p;
  // The folders above, down to two levels below the root (/home/USER, /tmp/X): no system folder
  // (/dev, /etc) is a package.
  for (fs::path a = folder_; std::distance(a.begin(), a.end()) > 2; a = a.parent_path())
    if (fs::path p = packageIn(a, name); !p.empty()) return p;
  for (const std::string& d : ros_)
    if (fs::path p = packageIn(d, name); !p.empty()) return p;
  return {};
}

std::vector<fs::path> FileSearch::candidates(const std::string& name, const std::vector<std::string>& dirs, std::string& looked) {
  static const std::string kPackage = "package://", kFile = "file://";
  if (name.rfind(kPackage, 0) == 0) {
    const std::string rest = name.substr(kPackage.size());
    const std::size_t slash = rest.find('/');
    const std::string pkg = rest.substr(0, slash), inner = slash == std::string::npos ? "" : rest.substr(slash + 1);
    const fs::path at = package(pkg);
    if (at.empty()) {
      looked = "no package folder '" + oneLine(pkg) + "' in " + (package_paths_.empty() ? "" : "--package-path " + listed(package_paths_) + ", ") +
               "the folders above " + oneLine(folder_.string()) + (ros_.empty() ? "" : ", ROS_PACKAGE_PATH " + listed(ros_)) +
               " (pass --package-path DIR)";
      return {};
    }
    const fs::path root = canonicalOr(at);
    if (std::find(roots_.begin(), roots_.end(), root) == roots_.end()) roots_.push_back(root);
    looked = "looked in package '" + oneLine(pkg) + "' at " + oneLine(at.string());
    return {at / inner};
  }
  const std::string plain = name.rfind(kFile, 0) == 0 ? name.substr(kFile.size()) : name;
  std::vector<fs::path> out;
  std::string where;
  for (const std::string& d : dirs) {
    const fs::path base = fs::path(d).is_absolute() ? fs::path(d) : folder_ / d;
    out.push_back(fs::path(plain).is_absolute() ? fs::path(plain) : base / plain);
    out.push_back(base / fs::path(plain).filename());
    where += (where.empty() ? "" : ", ") + oneLine(base.string());
  }
  looked = "looked in " + where;
  return out;
}

bool FileSearch::allowed(const fs::path& real) const {
  return std::any_of(roots_.begin(), roots_.end(), [&](const fs::path& r) { return inside(r, real); });
}

std::string FileSearch::roots() const {
  std::string out = "the model's folder " + folder_.string();
  for (std::size_t i = 1; i < roots_.size(); ++i) out += ", " + roots_[i].string();
  return out;
}

}  // namespace dyn::model_file::detail
