// Reading an input file (config, gains, submission, results to replay): a regular file only,
// opened without blocking, read with a size limit, and required to be UTF-8 text; see config.h.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "labs/config.h"
#include "labs/utf8.h"

namespace dyn {

namespace {

// What a non-regular file is, for "expected a regular file, got ...".
const char* fileKind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "something other than a file";
}

// "E9": one byte in hex.
std::string hexByte(char c) {
  char s[4];
  std::snprintf(s, sizeof s, "%02X", static_cast<unsigned char>(c));
  return s;
}

// Closes the descriptor on every way out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::string readTextFile(const std::string& file, std::size_t max_bytes) {
  // O_NONBLOCK: opening a FIFO with no writer returns at once instead of waiting for one; the
  // fstat below then refuses it (and devices, directories, sockets) before anything is read.
  const Fd in{::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY)};
  if (in.fd < 0) throw InputError(file, "", std::string("expected a readable file (cannot open it: ") + std::strerror(errno) + ")");
  struct stat st {};
  if (::fstat(in.fd, &st) != 0) throw InputError(file, "", std::string("expected a readable file (") + std::strerror(errno) + ")");
  if (!S_ISREG(st.st_mode)) throw InputError(file, "", std::string("expected a regular file, got ") + fileKind(st.st_mode));
  const auto tooBig = [&](std::size_t size) {
    return InputError(file, "", "expected at most " + std::to_string(max_bytes) + " bytes, the file has " +
                                    (size ? std::to_string(size) : "more"));
  };
  if (std::size_t(st.st_size) > max_bytes) throw tooBig(std::size_t(st.st_size));
  // Read to the end (the size may change under us): at most max_bytes + 1 bytes.
  std::string text;
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(in.fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw InputError(file, "", std::string("expected a readable file (reading it failed: ") + std::strerror(errno) + ")");
    if (n == 0) break;
    text.append(buf, std::size_t(n));
    if (text.size() > max_bytes) throw tooBig(0);
  }
  checkUtf8Text(text, file);
  return text;
}

void checkUtf8Text(const std::string& text, const std::string& file) {
  // A Windows editor's "Unicode" is UTF-16: say so rather than point at its first odd byte.
  if (text.size() >= 2 && ((text[0] == '\xFF' && text[1] == '\xFE') || (text[0] == '\xFE' && text[1] == '\xFF')))
    throw InputError(file, "", "expected UTF-8 text, the file is UTF-16 (it starts with the byte order mark " +
                                   hexByte(text[0]) + " " + hexByte(text[1]) +
                                   "); save it as UTF-8");
  // A NUL would end the text for C-string readers: nothing after it may be silently ignored.
  if (const auto nul = text.find('\0'); nul != std::string::npos)
    throw InputError(file, "", "expected UTF-8 text, byte 0x00 (NUL) at offset " + std::to_string(nul) +
                                   " is not allowed (is the file UTF-16 without a byte order mark?)");
  if (const auto bad = utf8ErrorAt(text); bad != std::string::npos)
    throw InputError(file, "", "expected UTF-8 text, byte 0x" + hexByte(text[bad]) +
                                   " at offset " + std::to_string(bad) + " is not valid UTF-8");
}

json loadJsonFile(const std::string& file, std::size_t max_bytes) {
  std::string text = readTextFile(file, max_bytes);
  // A UTF-8 byte order mark (Notepad writes one) is accepted: it says "UTF-8", which this is.
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
  return parseJsonText(text, file);
}

}  // namespace dyn
