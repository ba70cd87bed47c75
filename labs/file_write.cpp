// Checked, atomic file writes; see file_write.h.
#include "labs/file_write.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace dyn {
namespace {

// what(): "cannot write PATH: <strerror>", code(): the errno.
[[noreturn]] void fail(const std::string& path, int err) {
  throw std::system_error(err, std::generic_category(), "cannot write " + path);
}

bool deferred = false;

std::string folderOf(const std::string& path) {
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return dir.empty() ? "." : dir;
}

}  // namespace

bool writeFaultInjected(const std::string& file_name) {
  const char* spec = std::getenv("DYNLAB_FAULT_INJECTION");
  if (!spec || file_name.empty()) return false;
  // Comma-separated entries; ours are enospc:SUFFIX.
  const std::string s = spec;
  for (std::size_t at = 0; at <= s.size();) {
    std::size_t end = s.find(',', at);
    if (end == std::string::npos) end = s.size();
    const std::string entry = s.substr(at, end - at);
    if (entry.rfind("enospc:", 0) == 0) {
      const std::string want = entry.substr(7);
      if (!want.empty() && file_name.size() >= want.size() &&
          file_name.compare(file_name.size() - want.size(), want.size(), want) == 0)
        return true;
    }
    at = end + 1;
  }
  return false;
}

void deferDurability(bool defer) { deferred = defer; }

void syncFileSystem(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(path, errno);
  const int rc = ::syncfs(fd), err = errno;
  ::close(fd);
  if (rc != 0) fail(path, err);
}

void syncDirectory(const std::string& dir) {
  if (deferred) return;
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) fail(dir, errno);
  const int rc = ::fsync(fd), err = errno;
  ::close(fd);
  // Some file systems cannot fsync a folder (EINVAL): nothing more can be done there.
  if (rc != 0 && err != EINVAL) fail(dir, err);
}

void writeFileChecked(const std::string& path, std::string_view contents, bool durable) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail(path, errno);
  // Any failure from here on: the temporary file goes, the error names the final path.
  const auto abandon = [&](int err) {
    ::close(fd);
    ::unlink(tmp.c_str());
    fail(path, err);
  };
  const bool injected = writeFaultInjected(std::filesystem::path(path).filename().string());
  const std::size_t limit = injected ? contents.size() / 2 : contents.size();
  std::size_t done = 0;
  while (done < limit) {
    const ssize_t n = ::write(fd, contents.data() + done, limit - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) abandon(errno);
    done += std::size_t(n);
  }
  if (injected) abandon(ENOSPC);
  if (!deferred && ::fsync(fd) != 0 && errno != EINVAL) abandon(errno);
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(path, err);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(path, err);
  }
  if (durable) syncDirectory(folderOf(path));
}

}  // namespace dyn
