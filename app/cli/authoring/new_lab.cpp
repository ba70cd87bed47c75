// dynlab new-lab NAME --from LAB: a new data-defined lab, copied from one (labs/generic/data_lab.h).
// The copy is a lab folder at once: LAB.json becomes NAME.json with "lab": NAME, and every example's and
// instructor answer's "lab" follows. Its README.md and handout.md are new, not LAB's: a starting text that
// names NAME, whose handout builds from any data lab's JSON (LAB's prose names LAB's joints and path
// segments, which the first edit of the JSON removes). It is staged beside its destination and renamed
// into place, so a folder NAME is there whole or not at all; symbolic links in the source are not
// followed (noted). It ends with the command to run next, runnable as printed.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <unistd.h>

#include "app/cli/commands.h"
#include "grading/escape.h"
#include "labs/generic/data_lab.h"
#include "labs/generic/lab_folders.h"
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

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out.flush()) throw std::runtime_error("cannot write " + file.string());
}

// The new lab's handout prose: placeholders every data lab's JSON has, and what to write where.
std::string starterHandout(const std::string& name, const std::string& from) {
  return "<!-- The prose of the " + name + " handout (`dynlab handout " + name + "`), started by `dynlab new-lab " + name +
         " --from " + from + "`: replace each paragraph with your own. A \"{/json/pointer}\" is replaced by the value there\n"
         "in " + name + ".json (a number or a string) when the handout is generated; one naming nothing stops the handout, and\n"
         "`dynlab check-lab " + name + "` says where. \"## Mechanism\" and \"## Exercise\" are required; further sections\n"
         "(\"## Hints\") follow the generated gains, submission and rubric. The " + from + " lab's handout.md in the dynlab\n"
         "tree is a worked example. Comments like this one are not shown to students. -->\n\n"
         "## Mechanism\n\n"
         "The mechanism is the model file `{/model_file}`. (Describe its bodies and joints, the loops it closes, the joints\n"
         "the motors drive and the tool, and the lecture's equations they stand for.) The simulator integrates it with\n"
         "{/simulation/integrator} at dt = {/simulation/dt} s for {/simulation/duration} s.\n\n"
         "## Exercise\n\n"
         "(Say what the tool must do, which control laws the submission may choose and what each gain means.)\n"
         "Run `dynlab run " + name + " --gains my.json --video` and watch the run.\n\n"
         "## Hints\n\n"
         "* (What to plot first, and what to compare.)\n";
}

// The new lab's README (for whoever maintains the lab; students read the handout).
std::string starterReadme(const std::string& name, const std::string& from, const std::string& title) {
  return "# Lab: " + name + " — " + title + " (data only)\n\n"
         "<!-- Started by `dynlab new-lab " + name + " --from " + from + "`: say here what the exercise teaches and what\n"
         "you measured (`dynlab check-lab " + name + "` prints the shares and the passive drift). -->\n\n"
         "This folder has no C++: `" + name + ".json` (the exercise: the model file, the actuated joints, the tool, the\n"
         "path, the metrics and the rubric), the model file it names, `handout.md` (the prose of `dynlab handout " + name + "`),\n"
         "`examples/` (submissions students may start from) and `instructor/` (full-credit answers, staff only).\n\n"
         "Check it with `dynlab check-lab " + name + "` (add `--labs DIR` when this folder is in DIR, outside the dynlab\n"
         "tree): every check of the lab contract, the handout and this README.\n";
}

// instructor/README.md: the staff's page of the new lab (the source lab's answer is not this one's).
std::string starterInstructorNotes(const std::string& name, const std::string& from) {
  return "# Lab " + name + ": instructor files (course staff only)\n\n"
         "Left out of the student copy. `good.json` here began as a copy of " + from + "'s answer with its `\"lab\"`\n"
         "renamed: replace it with this exercise's full-credit answer (check-lab requires it to score at least 90 %),\n"
         "keep `lessons/` to the pairs this rubric states, and write the answer's gains and grade here.\n";
}

}  // namespace

int newLab(const NewLabArgs& args) {
  if (!std::regex_match(args.name, std::regex("[a-z][a-z0-9_]{0,39}")))
    return fail("NAME \"" + args.name + "\": expected a lab name of lowercase letters, digits and _, starting with a letter (at most 40)");
  // Written into the first --labs folder, else the first DYNLAB_LABS folder, else the tree's labs/.
  const std::vector<generic::LabsFolder> env = generic::labsFoldersFromEnvironment();
  const fs::path root = !args.labs.empty() ? fs::path(args.labs.front()) : !env.empty() ? fs::path(env.front().path) : fs::path(labsRoot());
  const fs::path src = fs::path(defaultConfigPath(args.from)).parent_path();
  if (!generic::isDataLabFolder(src.string(), args.from)) {
    if (findLab(args.from))
      return fail("--from " + args.from + ": a C++ lab; new-lab copies data-defined labs (a folder with LAB.json and no .cpp or .h), e.g. fivebar");
    return fail("--from " + args.from + ": no lab folder " + src.string() + " (a lab outside the dynlab tree: --labs DIR)");
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
    std::string title = args.name;
    try {
      title = loadJsonFile((stage / (args.name + ".json")).string()).value("title", args.name);
    } catch (const std::exception&) {
    }
    writeText(stage / "handout.md", starterHandout(args.name, args.from));
    // The source lab's staff notes name its answer's gains and grade: not this lab's.
    if (fs::is_directory(stage / "instructor")) writeText(stage / "instructor" / "README.md", starterInstructorNotes(args.name, args.from));
    writeText(stage / "README.md", starterReadme(args.name, args.from, title.substr(0, title.find(": "))));
    fs::rename(stage, dest);
  } catch (const std::exception& e) {
    fs::remove_all(stage, ec);
    std::fprintf(stderr, "error: dynlab new-lab: %s: %s (nothing written)\n", termName(dest.string()).c_str(), termName(e.what(), 1000).c_str());
    return 1;
  }
  // Paths as shell words (quoted when they hold a space or a quote), escaped for the terminal.
  const auto shown = [](const fs::path& p) { return termText(shellWord(p.string())); };
  std::printf("dynlab new-lab: %s, a copy of %s\n", shown(dest).c_str(), termText(args.from).c_str());
  for (const auto& s : skipped) std::printf("  not copied (a link or special file): %s\n", termName(s).c_str());
  // The command as it runs from here: this dynlab, and the folder as given (a relative one from this folder).
  const std::string labs = args.labs.empty() ? "" : " --labs " + shellWord(args.labs.front());
  std::printf("  next: edit %s (model_file, actuated, tool, trajectory, metrics, rubric),\n"
              "        handout.md and README.md beside it; then run, until every check passes:\n"
              "    %s\n",
              shown(dest / (args.name + ".json")).c_str(), termText(dynlabProgram() + " check-lab " + args.name + labs).c_str());
  return 0;
}

}  // namespace dyn::app
