// The submission-selection rule shared by the batch and run_autograder; see submission_file.h.
#include "app/cli/course/submission_file.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <vector>

namespace fs = std::filesystem;

namespace dyn::app {
namespace {

constexpr int kMaxDepth = 8;            // deeper entries are not looked at
constexpr std::size_t kMaxEntries = 10000;  // nor entries past this many (a hostile tree)

bool endsWithJson(const std::string& name) {
  if (name.size() <= 5) return false;
  std::string ext = name.substr(name.size() - 5);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".json";
}

bool skippedName(const std::string& name) { return name.empty() || name[0] == '.' || name == "__MACOSX"; }

}  // namespace

std::string refusedSubmissionFile(const fs::path& file, const fs::path& root, fs::path& resolved) {
  std::error_code ec;
  const fs::path real_root = fs::weakly_canonical(fs::absolute(root), ec);
  resolved = fs::absolute(file);
  if (fs::is_symlink(fs::symlink_status(file, ec))) {
    resolved = fs::weakly_canonical(resolved, ec);
    const auto [end, _] = std::mismatch(real_root.begin(), real_root.end(), resolved.begin(), resolved.end());
    if (ec || end != real_root.end() || resolved == real_root)
      return "the JSON file is a symbolic link to something outside the submission, so it was not read; upload the file "
             "itself (not a link)";
  }
  struct stat st {};
  if (::stat(resolved.c_str(), &st) != 0) return "the JSON file is a link to nothing, so it was not read";
  if (!S_ISREG(st.st_mode)) {
    const char* kind = S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISDIR(st.st_mode) ? "a folder"
                       : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device" : S_ISSOCK(st.st_mode) ? "a socket" : "not a regular file";
    return std::string("the JSON file is ") + kind + ", not a regular file, so it was not read; upload one ordinary file";
  }
  return "";
}

SubmissionFile chooseSubmissionFile(const fs::path& dir) {
  SubmissionFile out;
  std::vector<std::pair<int, fs::path>> candidates;  // (depth, path relative to dir)
  std::error_code ec;
  std::size_t seen = 0;
  fs::recursive_directory_iterator it(dir, fs::directory_options::none, ec), end;
  if (ec) {
    out.problem = "the submission folder cannot be read";
    return out;
  }
  for (; it != end && seen < kMaxEntries; it.increment(ec), ++seen) {
    if (ec) break;
    const std::string name = it->path().filename().string();
    std::error_code e2;
    const bool folder = it->is_directory(e2);  // a link to a folder counts as one (never entered)
    if (skippedName(name) || (folder && it.depth() + 1 >= kMaxDepth)) {
      if (folder && !it->is_symlink(e2)) it.disable_recursion_pending();
      continue;
    }
    if (!folder && endsWithJson(name)) candidates.push_back({it.depth(), it->path().lexically_relative(dir)});
  }
  if (ec) {
    out.problem = "the submission folder cannot be read";
    return out;
  }
  std::sort(candidates.begin(), candidates.end());
  const fs::path* chosen = nullptr;
  int named = 0, depth = -1;
  for (const auto& [d, rel] : candidates)
    if (rel.filename() == "submission.json" && (depth < 0 || d == depth)) {
      if (!named) chosen = &rel;
      depth = d;
      ++named;
    }
  if (named > 1) chosen = nullptr;
  if (!chosen && named == 0 && candidates.size() == 1) chosen = &candidates[0].second;
  if (!chosen) {
    out.problem = candidates.empty() ? "no JSON file was found in the submission"
                                     : "the submission has several JSON files and none is the one submission.json, so the "
                                       "grader cannot tell which one to grade";
    return out;
  }
  out.name = chosen->generic_string();
  fs::path resolved;
  out.problem = refusedSubmissionFile(dir / *chosen, dir, resolved);
  if (out.problem.empty()) out.file = resolved;
  return out;
}

int printSubmissionFile(const std::string& dir) {
  const SubmissionFile s = chooseSubmissionFile(dir);
  if (!s.problem.empty()) {
    std::printf("%s\n", s.problem.c_str());
    return 2;
  }
  std::printf("%s\n", s.file.c_str());
  return 0;
}

}  // namespace dyn::app
