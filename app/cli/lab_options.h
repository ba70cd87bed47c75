// The options every dynlab command that names a lab takes, added in one place (main.cpp calls
// addLabOptions once, after every subcommand exists): --labs DIR, a folder of lab folders outside
// the dynlab tree (repeatable), and the DYNLAB_LABS list read with it (labs/generic/lab_folders.h).
#pragma once
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace dyn::app {

struct LabOptions {
  std::vector<std::string> labs;    // --labs DIR, in the order given
  std::vector<CLI::App*> commands;  // the subcommands that take them
};

// Adds --labs to each subcommand of cli that names a lab: list, run, figure, grade, autograder,
// schema, ui, compare, lessons, check-lab, new-lab, bench, handout, map.
void addLabOptions(CLI::App& cli, LabOptions& o);

// After parsing, when one of those commands was chosen: registers the labs of each --labs folder,
// then of each DYNLAB_LABS folder, after the tree's, and sets DYNLAB_LABS to every folder in use
// (absolute), so the dynlab processes this one starts (check-lab's, a batch's graders, the window)
// find the same labs. Returns 0, or 2 after one line on stderr (a missing folder, a name clash).
int useLabOptions(const LabOptions& o);

// The words that select the lab's folder again in a printed command: " --labs DIR" (a shell word)
// for a lab outside the tree, else "".
std::string labsWords(const std::string& lab);

}  // namespace dyn::app
