// dynlab new-lab NAME --from LAB: a new data-defined lab, copied from one (labs/generic/data_lab.h).
// The copy is a lab folder at once: LAB.json becomes NAME.json with "lab": NAME, and every example's and
// instructor answer's "lab" follows. It is staged beside its destination and renamed into place, so a
// folder NAME is there whole or not at all; symbolic links in the source are not followed (noted).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <unistd.h>

#include "app/commands.h"
#include "labs/generic/data_lab.h"
#include "labs/utf8.h"

namespace dyn::app {
namespace {

namespace fs = std::filesystem;

// One line on stderr, whatever a name or path given holds (a newline, an ESC): escaped and clipped.
int fail(const std::string& what) {
  std::fprintf(stderr, "error: dynlab new-lab: %s\n", termName(what, 1000).c_str());
  return 2;
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// "lab": "<from>" → "lab": "<to>" in a JSON file's text, keeping its layout; false if it has no such key.
bool renameLab(const fs::path& file, const std::string& from, const std::string& to) {
  std::string text = readAll(file);
  const std::regex key("\"lab\"(\\s*):(\\s*)\"" + from + "\"");
  if (!std::regex_search(text, key)) return false;
  text = std::regex_replace(text, key, "\"lab\"$1:$2\"" + to + "\"", std::regex_constants::format_first_only);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << text;
  return bool(out);
}

}  // namespace

int newLab(const NewLabArgs& args) {
  if (!std::regex_match(args.name, std::regex("[a-z][a-z0-9_]{0,39}")))
    return fail("NAME \"" + args.name + "\": expected a lab name of lowercase letters, digits and _, starting with a letter (at most 40)");
  const fs::path root = args.labs.empty() ? fs::path(labsRoot()) : fs::path(args.labs);
  const fs::path src = fs::path(defaultConfigPath(args.from)).parent_path();
  if (!generic::isDataLabFolder(src.string(), args.from)) {
    if (findLab(args.from))
      return fail("--from " + args.from + ": a C++ lab; new-lab copies data-defined labs (a folder with LAB.json and no .cpp or .h), e.g. fivebar");
    return fail("--from " + args.from + ": no lab folder " + src.string());
  }
  if (findLab(args.name)) return fail("NAME " + args.name + ": a lab of that name exists");
  std::error_code ec;
  if (!fs::is_directory(root, ec)) return fail("--labs " + root.string() + ": expected an existing folder");
  const fs::path dest = root / args.name;
  if (fs::exists(fs::symlink_status(dest, ec))) return fail(dest.string() + ": exists; nothing written");

  // Stage the copy beside the destination, then rename it into place.
  const fs::path stage = root / ("." + args.name + ".new-lab-" + std::to_string(::getpid()));
  fs::remove_all(stage, ec);
  std::vector<std::string> skipped;
  try {
    fs::create_directory(stage);
    for (auto it = fs::recursive_directory_iterator(src); it != fs::recursive_directory_iterator(); ++it) {
      const fs::path rel = fs::relative(it->path(), src);
      const auto st = it->symlink_status();
      if (fs::is_symlink(st)) {
        skipped.push_back(rel.string());
        it.disable_recursion_pending();
        continue;
      }
      fs::path to = stage / rel;
      if (rel == fs::path(args.from + ".json")) to = stage / (args.name + ".json");
      if (fs::is_directory(st)) fs::create_directory(to);
      else if (fs::is_regular_file(st)) fs::copy_file(it->path(), to);
      else skipped.push_back(rel.string());
    }
    if (!renameLab(stage / (args.name + ".json"), args.from, args.name))
      throw std::runtime_error(args.from + ".json has no \"lab\": \"" + args.from + "\"");
    for (const char* sub : {"examples", "instructor"})
      if (fs::is_directory(stage / sub))
        for (const auto& e : fs::recursive_directory_iterator(stage / sub))
          if (e.is_regular_file() && e.path().extension() == ".json") renameLab(e.path(), args.from, args.name);
    fs::rename(stage, dest);
  } catch (const std::exception& e) {
    fs::remove_all(stage, ec);
    std::fprintf(stderr, "error: dynlab new-lab: %s: %s (nothing written)\n", termName(dest.string()).c_str(), termName(e.what(), 1000).c_str());
    return 1;
  }
  std::printf("dynlab new-lab: %s, a copy of %s\n", termName(dest.string()).c_str(), termName(args.from).c_str());
  for (const auto& s : skipped) std::printf("  not copied (a link or special file): %s\n", termName(s).c_str());
  std::printf("  next: edit %s (model_file, actuated, tool, trajectory, metrics, rubric) and handout.md,\n"
              "        then `dynlab check-lab %s` until every check passes\n",
              termName((dest / (args.name + ".json")).string()).c_str(), args.name.c_str());
  return 0;
}

}  // namespace dyn::app
