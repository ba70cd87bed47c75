// Python ↔ JSON and traces; see convert.h.
#include "app/python/convert.h"

#include <pybind11/numpy.h>

namespace dyn::python {

json toJson(py::handle o, const std::string& where) {
  if (o.is_none()) return nullptr;
  // bool before int: Python's True is an int.
  if (py::isinstance<py::bool_>(o)) return o.cast<bool>();
  if (py::isinstance<py::int_>(o)) {
    const long long v = o.cast<long long>();
    return v;
  }
  if (py::isinstance<py::float_>(o)) return o.cast<double>();
  if (py::isinstance<py::str>(o)) return o.cast<std::string>();
  if (py::isinstance<py::dict>(o)) {
    json out = json::object();
    for (const auto& [k, v] : o.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k))
        throw py::type_error(where + ": expected str keys, got " + std::string(py::str(py::type::of(k).attr("__name__"))));
      const std::string key = k.cast<std::string>();
      out[key] = toJson(v, (where == "/" ? "" : where) + "/" + key);
    }
    return out;
  }
  if (py::isinstance<py::list>(o) || py::isinstance<py::tuple>(o)) {
    json out = json::array();
    std::size_t i = 0;
    for (const auto& v : o) out.push_back(toJson(v, (where == "/" ? "" : where) + "/" + std::to_string(i++)));
    return out;
  }
  // NumPy scalars (np.float64 is a float already; np.int64, np.float32, np.bool_ are not).
  const py::module_ np = py::module_::import("numpy");
  if (py::isinstance(o, np.attr("bool_"))) return o.attr("item")().cast<bool>();
  if (py::isinstance(o, np.attr("integer"))) return o.attr("item")().cast<long long>();
  if (py::isinstance(o, np.attr("floating"))) return o.attr("item")().cast<double>();
  throw py::type_error(where + ": expected JSON data (dict, list, str, int, float, bool or None), got " +
                       std::string(py::str(py::type::of(o).attr("__name__"))));
}

py::object toPython(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return py::none();
    case json::value_t::boolean: return py::bool_(v.get<bool>());
    case json::value_t::number_integer: return py::int_(v.get<long long>());
    case json::value_t::number_unsigned: return py::int_(v.get<unsigned long long>());
    case json::value_t::number_float: return py::float_(v.get<double>());
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
  if (py::isinstance<py::str>(o)) {
    path = o.cast<std::string>();
    return true;
  }
  const py::module_ os = py::module_::import("os");
  if (py::isinstance(o, os.attr("PathLike"))) {
    path = py::str(os.attr("fspath")(o)).cast<std::string>();
    return true;
  }
  return false;
}

}  // namespace dyn::python
