// The course commands: `dynlab handout` (the student handout of a lab, app/cli/course/handout.cpp) and
// `dynlab map` (a stability/score map over two gains or parameters, app/cli/figures/map.cpp). Registered on the
// command line by CourseCommands, so main.cpp only constructs it and asks it to run.
#pragma once
#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace dyn::app {

struct HandoutArgs {
  std::string lab, out, config, format = "md,html", student;
};

struct MapArgs {
  std::string lab, x, y, metric, out, config, gains, data;
  std::optional<double> duration;
  bool sim = false;
  int jobs = 0;  // threads for --sim (0: every core)
};

// The handout as `dynlab handout` writes it (its Markdown, and the lab's title), nothing written;
// throws InputError on bad input (check-lab builds it this way).
struct HandoutText {
  std::string markdown, title;
};
HandoutText handoutText(const HandoutArgs& args);

// Each returns the exit code: 0 written, 1 a write failed, 2 bad input (one line, nothing written).
int handout(const HandoutArgs& args);
int map(const MapArgs& args);

class CourseCommands {
 public:
  explicit CourseCommands(CLI::App& cli);
  bool chosen() const { return *handout_ || *map_; }
  int run() const;

 private:
  HandoutArgs handout_args_;
  MapArgs map_args_;
  CLI::App* handout_ = nullptr;
  CLI::App* map_ = nullptr;
};

}  // namespace dyn::app
