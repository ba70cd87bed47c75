// Python ↔ JSON and traces; see convert.h.
#include "app/python/convert.h"

#include <cmath>

#include <pybind11/numpy.h>

namespace dyn::python {

namespace {

// A key as a JSON Pointer token (RFC 6901), as the CLI's paths write it.
std::string pointerToken(const std::string& key) {
  std::string out;
  for (const char c : key) out += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
  return out;
}

std::string typeName(py::handle o) { return py::str(py::type::of(o).attr("__name__")); }

// One conversion: the source named in messages and the JSON text counted so far.
struct Converter {
  const std::string& source;
  std::size_t bytes = 0;

  void count(std::size_t n, const std::string& path) {
    bytes += n;
    if (bytes > kMaxPythonJsonBytes)
      throw InputError(source, path, "expected at most " + std::to_string(kMaxPythonJsonBytes) +
                                         " bytes of JSON data (a submission file's limit); this holds more");
  }

  // str → UTF-8 (pybind11's cast would raise RuntimeError on a lone surrogate).
  std::string text(py::handle o, const std::string& path) {
    Py_ssize_t n = 0;
    const char* s = PyUnicode_AsUTF8AndSize(o.ptr(), &n);
    if (!s) {
      PyErr_Clear();
      throw InputError(source, path, "expected text UTF-8 can encode (it holds a lone surrogate)");
    }
    count(std::size_t(n) + 3, path);
    return std::string(s, std::size_t(n));
  }

  // An int as nlohmann reads one from a file: 64 bits signed or unsigned, else a double.
  json integer(py::handle o, const std::string& path) {
    count(8, path);
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow(o.ptr(), &overflow);
    if (v == -1 && PyErr_Occurred()) throw py::error_already_set();
    if (!overflow) return v;
    if (overflow > 0) {
      const unsigned long long u = PyLong_AsUnsignedLongLong(o.ptr());
      if (!PyErr_Occurred()) return u;
      PyErr_Clear();
    }
    const double d = PyLong_AsDouble(o.ptr());
    if (d == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      throw InputError(source, path, "expected a number a double can hold (within ±1.8e308), got an int of " +
                                         std::string(py::str(o.attr("bit_length")())) + " bits");
    }
    return d;
  }

  json operator()(py::handle o, const std::string& path, int depth) {
    if (o.is_none()) return count(4, path), nullptr;
    // bool before int: Python's True is an int.
    if (py::isinstance<py::bool_>(o)) return count(5, path), o.ptr() == Py_True;
    if (py::isinstance<py::int_>(o)) return integer(o, path);
    if (py::isinstance<py::float_>(o)) return count(8, path), PyFloat_AsDouble(o.ptr());
    if (py::isinstance<py::str>(o)) return text(o, path);
    const bool dict = py::isinstance<py::dict>(o), list = py::isinstance<py::list>(o) || py::isinstance<py::tuple>(o);
    // Nesting as the CLI's parser bounds it: a dict holding itself stops here, not in a stack overflow.
    if ((dict || list) && depth >= kMaxJsonDepth)
      throw InputError(source, path, "expected JSON nested at most " + std::to_string(kMaxJsonDepth) + " levels deep");
    const std::string prefix = path == "/" ? "" : path;
    if (dict) {
      json out = json::object();
      count(2, path);
      for (const auto& [k, v] : o.cast<py::dict>()) {
        if (!py::isinstance<py::str>(k)) throw py::type_error(path + ": expected str keys, got " + typeName(k));
        const std::string key = text(k, path);
        out[key] = (*this)(v, prefix + "/" + pointerToken(key), depth + 1);
      }
      return out;
    }
    if (list) {
      json out = json::array();
      count(2, path);
      std::size_t i = 0;
      for (const auto& v : o) out.push_back((*this)(v, prefix + "/" + std::to_string(i++), depth + 1));
      return out;
    }
    // NumPy scalars (np.float64 is a float already; np.int64, np.float32, np.bool_ are not): their
    // Python value, read as above.
    const py::module_ np = py::module_::import("numpy");
    if (py::isinstance(o, np.attr("bool_")) || py::isinstance(o, np.attr("integer")) || py::isinstance(o, np.attr("floating")))
      return (*this)(o.attr("item")(), path, depth);
    throw py::type_error(path + ": expected JSON data (dict, list, str, int, float, bool or None), got " + typeName(o));
  }
};

}  // namespace

json toJson(py::handle o, const std::string& source) {
  Converter convert{source};
  return convert(o, "/", 0);
}

py::object toPython(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return py::none();
    case json::value_t::boolean: return py::bool_(v.get<bool>());
    case json::value_t::number_integer: return py::int_(v.get<long long>());
    case json::value_t::number_unsigned: return py::int_(v.get<unsigned long long>());
    case json::value_t::number_float: {  // NaN, ±inf as None: what the same value is in a JSON file (null)
      const double x = v.get<double>();
      return std::isfinite(x) ? py::object(py::float_(x)) : py::object(py::none());
    }
    case json::value_t::string: return py::str(v.get<std::string>());
    case json::value_t::array: {
      py::list out;
      for (const auto& e : v) out.append(toPython(e));
      return out;
    }
    case json::value_t::object: {
      py::dict out;
      for (const auto& [k, e] : v.items()) out[py::str(k)] = toPython(e);
      return out;
    }
    default: return py::none();
  }
}

py::dict traceArrays(const Trace& trace) {
  py::dict out;
  const std::size_t rows = trace.rows(), cols = trace.columns.size();
  for (std::size_t c = 0; c < cols; ++c) {
    py::array_t<double> a(static_cast<py::ssize_t>(rows));
    double* p = a.mutable_data();
    for (std::size_t r = 0; r < rows; ++r) p[r] = trace.data[r * cols + c];
    out[py::str(trace.columns[c])] = std::move(a);
  }
  return out;
}

bool asPath(py::handle o, std::string& path) {
  py::object text;
  if (py::isinstance<py::str>(o)) {
    text = py::reinterpret_borrow<py::object>(o);
  } else {
    const py::module_ os = py::module_::import("os");
    if (!py::isinstance(o, os.attr("PathLike"))) return false;
    text = os.attr("fsdecode")(o);  // a bytes path as the file system's encoding reads it
  }
  Py_ssize_t n = 0;
  const char* s = PyUnicode_AsUTF8AndSize(text.ptr(), &n);
  if (!s) {  // a lone surrogate (os.fsdecode of bytes that are not UTF-8)
    PyErr_Clear();
    throw InputError(kArgument, "path", "expected a path UTF-8 can encode");
  }
  path.assign(s, std::size_t(n));
  // open() would stop at the NUL and read another file.
  if (path.find('\0') != std::string::npos) throw InputError(path, "", "expected a path without a NUL byte");
  return true;
}

}  // namespace dyn::python
