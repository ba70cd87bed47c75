// The submissions of a batch and their output folders; see batch.h.
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <set>

#include "app/cli/course/batch.h"
#include "app/cli/course/submission_file.h"
#include "grading/grade.h"
#include "grading/student.h"
#include "labs/config.h"

namespace fs = std::filesystem;

namespace dyn::app::batch {
namespace {

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool endsWithJson(const std::string& name) { return name.size() > 5 && lower(name.substr(name.size() - 5)) == ".json"; }

// macOS zip leftovers: __MACOSX/ folders and ._NAME AppleDouble files beside the real ones.
bool macOsLeftover(const std::string& name) { return name == "__MACOSX" || name.rfind("._", 0) == 0; }

// The entries of a folder, by name (byte order), without macOS leftovers.
std::vector<fs::directory_entry> listed(const fs::path& dir, std::error_code& ec) {
  std::vector<fs::directory_entry> v;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (!macOsLeftover(it->path().filename().string())) v.push_back(*it);
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.path().filename() < b.path().filename(); });
  return v;
}

// One student's folder: the file the shared rule chooses (app/cli/course/submission_file.h), else why none.
Submission fromFolder(const fs::directory_entry& folder) {
  const std::string name = folder.path().filename().string();
  const SubmissionFile chosen = chooseSubmissionFile(folder.path());
  Submission s{name + "/" + chosen.name, chosen.file, chosen.problem, {}};
  if (chosen.name.empty()) s.name = name + "/";
  return s;
}

// A name reduced to letters, digits, _ . - (no leading dot or dash), at most 60 bytes.
std::string cleaned(const std::string& raw) {
  std::string s;
  for (unsigned char c : raw) s += (std::isalnum(c) || c == '_' || c == '.' || c == '-') && c < 0x80 ? char(c) : '_';
  s.erase(0, s.find_first_not_of(".-"));
  if (s.size() > 60) s.resize(60);
  return s;
}

// The name an output folder would get before uniqueness: the file's stem, or the student's folder.
std::string stemOf(const Submission& s) {
  if (const auto slash = s.name.find('/'); slash != std::string::npos) return s.name.substr(0, slash);
  return s.name.substr(0, s.name.size() - 5);  // without ".json"
}

}  // namespace

Found findSubmissions(const fs::path& dir, const fs::path& out) {
  Found found;
  std::error_code ec;
  const auto entries = listed(dir, ec);
  if (ec) {
    found.error = "cannot read the submissions directory (" + ec.message() + ")";
    return found;
  }
  std::size_t other_files = 0, skipped_folders = 0;
  for (const auto& e : entries) {
    const std::string name = e.path().filename().string();
    std::error_code dir_ec;
    if (e.is_directory(dir_ec)) {
      // OUT inside DIR, and hidden folders (.git, .staging), are not students.
      if (name[0] == '.' || fs::equivalent(e.path(), out, dir_ec)) {
        ++skipped_folders;
        continue;
      }
      found.submissions.push_back(fromFolder(e));
    } else if (endsWithJson(name)) {
      // The same check as a folder's file: a link must stay inside DIR, and lead to a regular file.
      Submission s{name, {}, {}, {}};
      fs::path resolved;
      s.problem = refusedSubmissionFile(e.path(), dir, resolved);
      if (s.problem.empty()) s.file = resolved;
      found.submissions.push_back(std::move(s));
    } else {
      ++other_files;
    }
  }
  if (found.submissions.empty())
    found.error = "found no submissions: no *.json file at its top and no folder below it (one per student, as in a "
                  "Gradescope export); " + std::to_string(other_files) + " other file(s), " +
                  std::to_string(skipped_folders) + " hidden or output folder(s)";
  std::sort(found.submissions.begin(), found.submissions.end(),
            [](const Submission& a, const Submission& b) { return a.name < b.name; });
  return found;
}

void assignFolders(std::vector<Submission>& subs, const fs::path& out) {
  // How many submissions want each clean name (case folded: case-insensitive disks fold them too).
  std::map<std::string, int> wanted;
  for (const auto& s : subs) ++wanted[lower(cleaned(stemOf(s)))];
  std::set<std::string> taken;  // case folded
  // A folder in OUT that no batch wrote (no grade.log in it) is someone else's: never reused.
  const auto foreign = [&](const std::string& folder) {
    std::error_code ec;
    const auto st = fs::symlink_status(out / folder, ec);
    return fs::exists(st) && (!fs::is_directory(st) || !fs::exists(out / folder / "grade.log", ec));
  };
  for (auto& s : subs) {
    const std::string stem = stemOf(s), clean = cleaned(stem), base = clean.empty() ? "submission" : clean;
    const bool plain = !clean.empty() && clean == stem && wanted[lower(clean)] == 1 && lower(clean).rfind("gradebook", 0) != 0;
    const std::string hashed = base + "-" + hashHex(s.name).substr(0, 8);
    std::string folder = plain ? clean : hashed;
    // Taken or foreign: the hashed name, then a counter.
    for (int n = 2; taken.count(lower(folder)) || foreign(folder); ++n)
      folder = folder == clean ? hashed : hashed + "-" + std::to_string(n);
    taken.insert(lower(folder));
    s.folder = folder;
  }
}

namespace {

// The roster: name → student ID, one "NAME,ID" a line (split at the last comma, so a name may hold one).
std::map<std::string, std::string> readRoster(const std::string& file) {
  std::map<std::string, std::string> out;
  const std::string text = readTextFile(file, 4u << 20);
  std::size_t line_no = 0, at = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(at, end - at);
    at = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || (line_no == 1 && line == "submission,student")) continue;
    const std::string where = "line " + std::to_string(line_no);
    const std::size_t comma = line.rfind(',');
    if (comma == std::string::npos || comma == 0)
      throw InputError(file, where, "expected FILE_OR_FOLDER,STUDENT_ID");
    const std::string name = line.substr(0, comma), id = line.substr(comma + 1);
    if (const std::string problem = studentIdProblem(id); !problem.empty()) throw InputError(file, where, problem);
    if (!out.emplace(name, id).second) throw InputError(file, where, "expected each submission once, got \"" + name + "\" again");
  }
  return out;
}

}  // namespace

void assignStudents(std::vector<Submission>& subs, const std::string& roster) {
  const std::map<std::string, std::string> ids = roster.empty() ? std::map<std::string, std::string>{} : readRoster(roster);
  for (Submission& s : subs) {
    // The top name: a student's folder, or a file at the top ("alice.json" → alice).
    std::string name = s.name.substr(0, s.name.find('/'));
    if (const auto it = ids.find(name); it != ids.end()) {
      s.student = it->second;
      continue;
    }
    if (!roster.empty()) {
      if (s.problem.empty()) s.problem = "not in the roster " + roster + ": no student to grade it as";
      continue;
    }
    if (s.name.find('/') == std::string::npos && endsWithJson(name)) name = name.substr(0, name.size() - 5);
    if (const std::string problem = studentIdProblem(name); !problem.empty()) {
      if (s.problem.empty()) s.problem = "its name is not a student ID (" + problem + "): give the batch a --roster";
      continue;
    }
    s.student = name;
  }
}

}  // namespace dyn::app::batch
