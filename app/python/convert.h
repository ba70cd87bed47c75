// Between Python objects and the core's JSON and traces: the module's only conversions.
#pragma once
#include <pybind11/pybind11.h>

#include <string>

#include "labs/config.h"
#include "labs/trace.h"

namespace dyn::python {

namespace py = pybind11;

// JSON data from Python: dict (str keys), list/tuple, str, int, float, bool, None, and NumPy
// scalars. Anything else is a TypeError naming `where` (a JSON path).
json toJson(py::handle object, const std::string& where = "/");
py::object toPython(const json& value);
// A trace as {column: 1-D float64 array}, in the trace's column order.
py::dict traceArrays(const Trace& trace);
// A path given as str or os.PathLike, or nothing (false) if `object` is neither.
bool asPath(py::handle object, std::string& path);

}  // namespace dyn::python
