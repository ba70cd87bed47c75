// The lab-taking commands' shared options; see lab_options.h.
#include "app/cli/lab_options.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "grading/escape.h"
#include "labs/config.h"
#include "labs/generic/lab_folders.h"
#include "labs/lab.h"

namespace dyn::app {

void addLabOptions(CLI::App& cli, LabOptions& o) {
  static const char* const kCommands[] = {"list",  "run",     "figure",    "grade",   "autograder", "schema",  "ui",
                                          "compare", "lessons", "check-lab", "new-lab", "bench",      "handout", "map"};
  for (const char* name : kCommands) {
    CLI::App* sub = nullptr;
    try {
      sub = cli.get_subcommand(name);
    } catch (const CLI::OptionNotFound&) {
      continue;
    }
    const std::string help =
        std::string(name) == "new-lab"
            ? "The folder of lab folders to write the new lab into, searched for --from too (default: the first "
              "DYNLAB_LABS folder, else the dynlab tree's labs/); repeatable, the first is written into"
            : "A folder of lab folders outside the dynlab tree, e.g. your course's (repeatable; DYNLAB_LABS=DIR:DIR "
              "does the same): its labs are found after the tree's, under names no tree lab has";
    sub->add_option("--labs", o.labs, help)->type_name("DIR")->allow_extra_args(false);
    o.commands.push_back(sub);
  }
}

int useLabOptions(const LabOptions& o) {
  if (std::none_of(o.commands.begin(), o.commands.end(), [](const CLI::App* c) { return c->parsed(); })) return 0;
  std::vector<generic::LabsFolder> folders;
  for (const auto& dir : o.labs) folders.push_back({dir, "--labs"});
  for (const auto& f : generic::labsFoldersFromEnvironment()) folders.push_back(f);
  try {
    generic::useLabsFolders(folders);
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  std::string list;
  for (const auto& dir : generic::labsFoldersInUse()) list += (list.empty() ? "" : ":") + dir;
  if (list.empty()) ::unsetenv("DYNLAB_LABS");
  else ::setenv("DYNLAB_LABS", list.c_str(), 1);
  return 0;
}

std::string labsWords(const std::string& lab) {
  const LabEntry* e = findLab(lab);
  return e && !e->labs_folder.empty() ? " --labs " + shellWord(e->labs_folder) : "";
}

}  // namespace dyn::app
