// Output staging: everything a command writes goes to DIR/.staging-PID-N first (private to this
// process) and is moved into place only when the command succeeds, under an exclusive lock on DIR,
// so a failure never leaves half-written results and two concurrent commands into one DIR each
// publish a whole set (the later one wins), never a mix.
// Every write is checked through close (labs/file_write.h): a full disk is an exception naming
// the file with the system's error text, never a short file left as if it were valid.
#pragma once
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace dyn::app {

// OUT holds something in the way that dynlab did not write (a folder of the user's where dynlab
// puts plots/ or frames/): nothing is removed, and the command says so (the user's choice of OUT).
class OutputConflict : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A staged write that failed, said in one line on stderr ("error: WHAT not written: why"): the exit code
// is 2 for an OutputConflict (OUT is the user's choice and something of theirs is in the way: nothing
// was removed), else `other` (a disk or folder error; what was there before stays).
int notWritten(const std::string& what, const std::exception& e, int other);

class Staging {
 public:
  explicit Staging(const std::filesystem::path& out_dir);
  ~Staging();  // discards anything not committed
  std::filesystem::path path(const std::string& name) const { return staging_ / name; }
  void write(const std::string& name, const std::string& contents) const;
  // Names this command always owns in out_dir: on commit, any of them not staged this time is
  // removed, so a rerun never leaves a stale file (an old video.mp4) beside fresh results.
  void owns(std::vector<std::string> names) { owned_ = std::move(names); }
  // Moves every staged entry into out_dir (a file replaces the older one in one rename), removes
  // the staging dir and fsyncs out_dir, so the new results are on disk when commit returns. A folder
  // it would replace or remove must hold only what dynlab writes there (numbered .png/.svg/.pdf
  // files): else OutputConflict, before anything is touched.
  void commit();
  const std::filesystem::path& outDir() const { return out_; }

 private:
  std::filesystem::path out_, staging_;
  std::vector<std::string> owned_;
  bool committed_ = false;
};

// Writes a file atomically and durably (temporary name, fsync, rename, fsync of the folder).
void writeFileAtomic(const std::filesystem::path& path, const std::string& contents);

}  // namespace dyn::app
