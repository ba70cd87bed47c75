// What MuJoCo may read: the model file and every file it names, checked and read here, then handed to
// MuJoCo's virtual file system (mjVFS), so that what was checked is what is parsed. MuJoCo 2.2.2 looks
// a file up there by its name alone (no folder, any case) and reads the disk only when it is missing:
// every name the text gives a file (an attribute file, filename or file*, as <include>, <mesh>,
// <hfield>, <texture>, <skin> and URDF's <mesh filename> write them) is put there, either as the
// checked bytes of a regular file inside the folders packages.cpp allows (the model's, its ROS package,
// the packages it names) or, when no such file exists, as a
// one-byte stand-in that MuJoCo then reports as unreadable: MuJoCo never opens a FIFO, a device, a
// link out of the folder or a file past the limits. The names are found by scanning the text for
// attribute values (a lexical scan, not a parse: a name in a comment is checked too, harmlessly); which
// of a URDF's names are visuals MuJoCo discards is read from its parsed elements (urdf_read.cpp).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <set>

#include "physics/model_file/mujoco_call.h"
#include "physics/model_file/urdf_read.h"
#include "physics/util/utf8.h"

namespace dyn::model_file::detail {
namespace {

namespace fs = std::filesystem;

// A regular file's bytes, at most `limit`: opened without blocking (a FIFO swapped in after the check
// opens and is refused), its type and size taken from the open file. `who` starts each error.
std::string readRegular(const std::string& path, std::size_t limit, const std::string& who, const std::string& expected) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw ModelFileError(who + ": cannot be opened");
  struct stat st {};
  std::string bytes;
  try {
    if (::fstat(fd, &st) != 0) throw ModelFileError(who + ": cannot read its size");
    if (!S_ISREG(st.st_mode)) throw ModelFileError(who + ": not a regular file (expected " + expected + ")");
    if (std::size_t(st.st_size) > limit)
      throw ModelFileError(who + ": " + std::to_string(st.st_size) + " bytes, more than the " + std::to_string(limit) + " " + expected + " may have");
    bytes.resize(std::size_t(st.st_size) + 1);
    std::size_t got = 0;
    while (got < bytes.size()) {
      const ssize_t r = ::read(fd, bytes.data() + got, bytes.size() - got);
      if (r < 0) throw ModelFileError(who + ": cannot be read");
      if (r == 0) break;
      got += std::size_t(r);
    }
    if (got > limit) throw ModelFileError(who + ": grew past " + std::to_string(limit) + " bytes while read");
    bytes.resize(got);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return bytes;
}

// A model text's bytes checked: not blank, well-formed UTF-8.
void checkText(const std::string& s, const std::string& who, const std::string& expected) {
  if (s.find_first_not_of(" \t\r\n") == std::string::npos) throw ModelFileError(who + ": empty (expected " + expected + ")");
  if (const std::size_t at = utf8ErrorAt(s); at != std::string::npos) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", unsigned(static_cast<unsigned char>(s[at])));
    throw ModelFileError(who + ": byte " + hex + " at offset " + std::to_string(at) + " is not valid UTF-8 (model files are UTF-8)");
  }
}

// An attribute value with XML's character references and predefined entities replaced (as the parser
// will); false if it holds another entity.
bool unescape(const std::string& in, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] != '&') {
      out += in[i];
      continue;
    }
    const std::size_t end = in.find(';', i);
    if (end == std::string::npos) return false;
    const std::string e = in.substr(i + 1, end - i - 1);
    static const std::map<std::string, char> named{{"lt", '<'}, {"gt", '>'}, {"amp", '&'}, {"quot", '"'}, {"apos", '\''}};
    if (const auto it = named.find(e); it != named.end()) {
      out += it->second;
    } else if (e.size() > 1 && e[0] == '#') {
      const bool hex = e[1] == 'x' || e[1] == 'X';
      const std::string digits = e.substr(hex ? 2 : 1);
      if (digits.empty() || digits.size() > 8 || digits.find_first_not_of(hex ? "0123456789abcdefABCDEF" : "0123456789") != std::string::npos)
        return false;
      const unsigned long cp = std::stoul(digits, nullptr, hex ? 16 : 10);
      if (cp == 0 || cp > 0x10FFFF) return false;
      // UTF-8 of the code point (a name's byte at last).
      if (cp < 0x80) out += char(cp);
      else if (cp < 0x800) out += char(0xC0 | (cp >> 6)), out += char(0x80 | (cp & 0x3F));
      else if (cp < 0x10000) out += char(0xE0 | (cp >> 12)), out += char(0x80 | ((cp >> 6) & 0x3F)), out += char(0x80 | (cp & 0x3F));
      else out += char(0xF0 | (cp >> 18)), out += char(0x80 | ((cp >> 12) & 0x3F)), out += char(0x80 | ((cp >> 6) & 0x3F)), out += char(0x80 | (cp & 0x3F));
    } else {
      return false;
    }
    i = end;
  }
  return true;
}

std::string vfsKeyExtension(std::string ext) {
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

bool isNameChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == ':' || c == '.'; }

// The names of a URDF's visuals MuJoCo discards (its default; `discardvisual="false"` keeps them):
// those written only inside its <visual> elements (urdf_read.cpp); every name when the URDF is not
// well-formed XML, so that MuJoCo's parser, not a clash of two names, says what is wrong with it.
struct DiscardedVisuals {
  bool every = false;
  std::set<std::string> names;
  bool has(const std::string& name) const { return every || names.count(name) > 0; }
};

// Null for a file other than a URDF (no facts), or a URDF that keeps its visuals.
std::unique_ptr<DiscardedVisuals> discardedVisuals(const UrdfFacts* facts) {
  if (!facts || (facts->well_formed && facts->keeps_visuals)) return nullptr;
  auto out = std::make_unique<DiscardedVisuals>();
  out->every = !facts->well_formed;
  out->names = facts->visual_only;
  return out;
}

// Every `name = "value"` (or '…') in the text whose name starts with "file" (files) or is meshdir,
// texturedir or assetdir (folders), values unescaped. One pass over the text. The names in
// `visual_only` (a URDF's discarded visuals) go to `visuals` instead of `files`.
void scanNames(const std::string& text, const std::string& who, std::vector<std::string>& files, std::vector<std::string>& dirs,
               std::vector<std::string>& visuals, const DiscardedVisuals* visual_only) {
  for (std::size_t eq = text.find('='); eq != std::string::npos; eq = text.find('=', eq + 1)) {
    std::size_t e = eq;
    while (e > 0 && std::isspace(static_cast<unsigned char>(text[e - 1]))) --e;
    std::size_t b = e;
    while (b > 0 && isNameChar(text[b - 1])) --b;
    if (b == e) continue;
    const std::string name = text.substr(b, e - b);
    const bool file = name.rfind("file", 0) == 0, dir = name == "meshdir" || name == "texturedir" || name == "assetdir";
    if (!file && !dir) continue;
    std::size_t v = eq + 1;
    while (v < text.size() && std::isspace(static_cast<unsigned char>(text[v]))) ++v;
    if (v >= text.size() || (text[v] != '"' && text[v] != '\'')) continue;
    const std::size_t close = text.find(text[v], v + 1);
    if (close == std::string::npos) continue;
    std::string value;
    if (!unescape(text.substr(v + 1, close - v - 1), value))
      throw ModelFileError(who + ": " + name + "=\"" + oneLine(text.substr(v + 1, std::min<std::size_t>(close - v - 1, 80))) +
                           "\" holds an entity dynlab does not expand (write the file's name plainly)");
    if (value.empty()) continue;
    if (file && visual_only && visual_only->has(value)) visuals.push_back(value);
    else (file ? files : dirs).push_back(value);
  }
}

// MuJoCo's name for a file in its virtual file system: the name without its folder, any case.
std::string vfsKey(const std::string& name) {
  const std::size_t slash = name.find_last_of("/\\");
  std::string key = slash == std::string::npos ? name : name.substr(slash + 1);
  std::transform(key.begin(), key.end(), key.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return key;
}

}  // namespace

std::string readChecked(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw ModelFileError(path + ": no such file");
  if (!fs::is_regular_file(st)) throw ModelFileError(path + ": not a regular file (expected an MJCF or URDF file)");
  std::string s = readRegular(path, kMaxFileBytes, path, "a model file");
  checkText(s, path, "an MJCF or URDF file");
  return s;
}

void putFile(mjVFS* vfs, const std::string& path, const std::string& name, const std::string& bytes) {
  if (mj_makeEmptyFileVFS(vfs, name.c_str(), int(bytes.size())) != 0) throw ModelFileError(path + ": MuJoCo's virtual file system refused '" + name + "'");
  const int at = mj_findFileVFS(vfs, name.c_str());
  if (at < 0) throw ModelFileError(path + ": MuJoCo's virtual file system lost '" + name + "'");
  std::copy(bytes.begin(), bytes.end(), static_cast<char*>(vfs->filedata[at]));
}

bool isUrdfPath(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  return dot != std::string::npos && vfsKeyExtension(path.substr(dot)) == ".urdf";
}

std::vector<std::string> addReferencedFiles(const std::string& path, const std::string& bytes, mjVFS* vfs,
                                            const std::vector<std::string>& package_paths, const UrdfFacts* urdf) {
  std::error_code ec;
  const fs::path main = fs::canonical(path, ec);
  if (ec) throw ModelFileError(path + ": cannot resolve its folder (" + ec.message() + ")");
  const fs::path folder = main.parent_path();
  FileSearch search(folder, package_paths);
  // The texts to scan (the model, then each include found), every name found, and the folders named.
  std::vector<std::pair<std::string, std::string>> texts{{path, bytes}};  // (who, text)
  std::vector<std::string> dirs{""};
  std::map<std::string, fs::path> taken{{vfsKey(main.filename().string()), main}};  // VFS name → the file put there
  std::set<std::string> seen;  // names already handled
  std::vector<std::string> missing;
  std::size_t total = 0;
  for (std::size_t t = 0; t < texts.size(); ++t) {
    std::vector<std::string> files, visuals;
    std::vector<std::string> more_dirs;
    // A URDF's discarded visuals come last: MuJoCo's URDF reader keys meshes by file name and reads the
    // collision's, so a visual of the same name (meshes/visual/link1.obj beside meshes/collision/
    // link1.obj) is checked and left out rather than refused.
    const std::unique_ptr<DiscardedVisuals> discard = t == 0 ? discardedVisuals(urdf) : nullptr;
    scanNames(texts[t].second, texts[t].first, files, more_dirs, visuals, discard.get());
    const std::size_t visual_from = files.size();
    files.insert(files.end(), visuals.begin(), visuals.end());
    for (const std::string& d : more_dirs)
      if (std::find(dirs.begin(), dirs.end(), d) == dirs.end()) dirs.push_back(d);
    for (std::size_t n = 0; n < files.size(); ++n) {
      const std::string& name = files[n];
      if (!seen.insert(name).second) continue;
      if (seen.size() > std::size_t(kMaxAssetFiles))
        throw ModelFileError(path + ": names more than " + std::to_string(kMaxAssetFiles) + " files (meshes, textures, includes)");
      const std::string who = path + ": file '" + oneLine(name) + "'";
      // Where it may be (packages.cpp: package://, file://, the name or its last part under the model's
      // folder and each folder the file names: meshdir, texturedir, assetdir); the first that exists.
      fs::path found;
      std::string looked;
      for (const fs::path& c : search.candidates(name, dirs, looked))
        if (found.empty() && fs::exists(fs::symlink_status(c, ec))) found = c;
      const std::string key = vfsKey(name);
      if (found.empty()) {
        // None: a stand-in under its name, so that MuJoCo cannot read it from elsewhere.
        if (!taken.count(key)) {
          putFile(vfs, path, key, "\n");
          taken[key] = fs::path();
          missing.push_back("'" + oneLine(name) + "' not found (" + looked + ")");
        }
        continue;
      }
      const fs::path real = fs::canonical(found, ec);
      if (ec) throw ModelFileError(who + " is a link that leads nowhere (" + found.string() + ")");
      if (!search.allowed(real))
        throw ModelFileError(who + " resolves to " + real.string() + ", outside " + search.roots() +
                             " (dynlab reads the files a model names from its folder, the ROS package it is in, "
                             "the packages its package:// names find and --package-path folders)");
      if (const auto it = taken.find(key); it != taken.end()) {
        if (it->second == real || n >= visual_from) continue;  // the same file, or a discarded visual's: already there
        throw ModelFileError(who + ": another file named '" + key + "' is named too (MuJoCo finds files by name alone: rename one)");
      }
      const bool xml = [&] {
        const std::string ext = vfsKey(real.extension().string());
        return ext == ".xml" || ext == ".urdf";
      }();
      std::string data = readRegular(real.string(), xml ? kMaxFileBytes : kMaxAssetBytes, who, xml ? "an included model file" : "a mesh, texture or height field");
      // (MuJoCo's file table takes no empty file: its error would stop the process.)
      if (data.empty()) throw ModelFileError(who + ": empty (expected " + (xml ? "an included MJCF file" : "a mesh, texture or height field") + ")");
      total += data.size();
      if (total > kMaxAssetsBytes)
        throw ModelFileError(who + ": the files the model names pass " + std::to_string(kMaxAssetsBytes) + " bytes in all");
      if (xml) {
        checkText(data, who, "an included MJCF file");
        texts.emplace_back(who, data);
      }
      putFile(vfs, path, key, data);
      taken[key] = real;
    }
  }
  return missing;
}

}  // namespace dyn::model_file::detail
