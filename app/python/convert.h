// Between Python objects and the core's JSON and traces: the module's only conversions.
#pragma once
#include <pybind11/pybind11.h>

#include <cstddef>
#include <string>

#include "labs/config.h"
#include "labs/trace.h"

namespace dyn::python {

namespace py = pybind11;

// What `source` names inputs from Python in messages, where the CLI names a file.
inline const std::string kGainsSource = "<gains>", kSubmissionSource = "<submission>", kArgument = "<python>";

// The most JSON text a Python value may stand for (as a submission file may hold: 1 MiB).
inline constexpr std::size_t kMaxPythonJsonBytes = 1u << 20;

// JSON data from Python: dict (str keys), list/tuple, str, int, float, bool, None, and NumPy
// scalars, read as the CLI reads the same JSON from a file named `source`. Refused with an
// InputError (a ValueError) naming source and the JSON path, as the CLI's parser refuses a file:
// nesting deeper than kMaxJsonDepth (a dict holding itself), more than kMaxPythonJsonBytes of
// JSON text, an int no double holds, text UTF-8 cannot encode. Any other type is a TypeError
// naming the path. An int past 64 bits becomes a double, as nlohmann reads 1208925819614629174706176.
json toJson(py::handle object, const std::string& source);
// A JSON value as Python data; a non-finite number is None, as a JSON file holds it (null).
py::object toPython(const json& value);
// A trace as {column: 1-D float64 array}, in the trace's column order.
py::dict traceArrays(const Trace& trace);
// A path given as str or os.PathLike, or nothing (false) if `object` is neither. A path holding a
// NUL byte (which would name another file) is an InputError.
bool asPath(py::handle object, std::string& path);

}  // namespace dyn::python
