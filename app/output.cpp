// Staged, atomic output; see output.h.
#include "app/output.h"

#include <fstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace dyn::app {

void writeFileAtomic(const fs::path& path, const std::string& contents) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << contents;
    if (!f.good()) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);
}

Staging::Staging(const fs::path& out) : out_(out), staging_(out / ".staging") {
  fs::create_directories(out_);
  fs::remove_all(staging_);
  fs::create_directories(staging_);
}

Staging::~Staging() {
  std::error_code ec;
  if (!committed_) fs::remove_all(staging_, ec);
}

void Staging::write(const std::string& name, const std::string& contents) const {
  writeFileAtomic(path(name), contents);
}

void Staging::commit() {
  for (const auto& name : owned_)
    if (!fs::exists(staging_ / name)) fs::remove_all(out_ / name);
  for (const auto& e : fs::directory_iterator(staging_)) {
    const fs::path dest = out_ / e.path().filename();
    fs::remove_all(dest);
    fs::rename(e.path(), dest);
  }
  fs::remove_all(staging_);
  committed_ = true;
}

}  // namespace dyn::app
