// Staged, atomic output; see output.h.
#include "app/cli/output.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <system_error>

#include "labs/file_write.h"
#include "labs/utf8.h"

namespace fs = std::filesystem;

namespace dyn::app {

void writeFileAtomic(const fs::path& path, const std::string& contents) {
  writeFileChecked(path.string(), contents, true);
}

namespace {
// A staging folder's name: ".staging-PID-N", private to this process (N counts this process's stagings).
std::string stagingName() {
  static std::atomic<int> counter{0};
  return ".staging-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

// Staging folders left by a process that no longer runs (killed mid-command), and the shared
// ".staging" of older versions: removed. Another live process's staging is never touched.
void removeStale(const fs::path& out) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out, ec)) {
    const std::string name = e.path().filename().string();
    if (name == ".staging") {
      fs::remove_all(e.path(), ec);
      continue;
    }
    if (name.rfind(".staging-", 0) != 0) continue;
    const long pid = std::strtol(name.c_str() + 9, nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) fs::remove_all(e.path(), ec);
  }
}

// An exclusive flock on the folder itself (no lock file to leave behind), released on destruction.
struct FolderLock {
  int fd = -1;
  explicit FolderLock(const fs::path& dir) {
    fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) throw std::system_error(errno, std::generic_category(), "cannot open " + dir.string());
    while (::flock(fd, LOCK_EX) != 0)
      if (errno != EINTR) {
        const int err = errno;
        ::close(fd);
        throw std::system_error(err, std::generic_category(), "cannot lock " + dir.string());
      }
  }
  ~FolderLock() { ::close(fd); }
};
}  // namespace

Staging::Staging(const fs::path& out) : out_(out), staging_(out / stagingName()) {
  fs::create_directories(out_);
  removeStale(out_);
  fs::remove_all(staging_);
  fs::create_directories(staging_);
}

Staging::~Staging() {
  std::error_code ec;
  if (!committed_) fs::remove_all(staging_, ec);
}

void Staging::write(const std::string& name, const std::string& contents) const {
  // Staged files are fsynced; the folder is synced once, on commit. The error names the file the
  // user knows (OUT/name), not its staging copy.
  try {
    writeFileChecked(path(name).string(), contents, false);
  } catch (const std::system_error& e) {
    throw std::system_error(e.code(), "cannot write " + (out_ / name).string());
  }
}

namespace {
// A folder dynlab may replace: its entries are only numbered figures (plots/03-force.png,
// frames/00042.png), which dynlab wrote; anything else is the user's.
void checkOurs(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(fs::symlink_status(dir, ec))) return;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string(), ext = e.path().extension().string();
    const bool ours = e.is_regular_file(ec) && !e.is_symlink(ec) && !name.empty() && name[0] >= '0' && name[0] <= '9' &&
                      (ext == ".png" || ext == ".svg" || ext == ".pdf");
    if (!ours)
      throw OutputConflict(dir.string() + " holds files dynlab did not write (" + name +
                           "): choose another --out, or move them away");
  }
}
}  // namespace

void Staging::commit() {
  // One commit into a folder at a time: a concurrent command's set lands whole before or after this one.
  const FolderLock lock(out_);
  // Nothing is removed unless everything that would be is dynlab's own.
  for (const auto& name : owned_) checkOurs(out_ / name);
  for (const auto& e : fs::directory_iterator(staging_)) checkOurs(out_ / e.path().filename());
  for (const auto& name : owned_)
    if (!fs::exists(staging_ / name)) fs::remove_all(out_ / name);
  for (const auto& e : fs::directory_iterator(staging_)) {
    const fs::path dest = out_ / e.path().filename();
    // rename() replaces a file in one step (the old one stays until then); a folder must go first.
    if (fs::is_directory(e.symlink_status()) || fs::is_directory(fs::symlink_status(dest))) fs::remove_all(dest);
    fs::rename(e.path(), dest);
  }
  fs::remove_all(staging_);
  syncDirectory(out_.string());
  committed_ = true;
}

int notWritten(const std::string& what, const std::exception& e, int other) {
  std::fprintf(stderr, "error: %s not written: %s\n", what.c_str(), termText(e.what()).c_str());
  return dynamic_cast<const OutputConflict*>(&e) ? 2 : other;
}

}  // namespace dyn::app
