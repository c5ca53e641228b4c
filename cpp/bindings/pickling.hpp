// Pickling of the bound classes at every protocol, 0 to 5.
//
// pybind11's py::pickle defines __getstate__ and __setstate__, which pickle reads only from
// protocol 2 on. Below that, and for a class with no pickling at all, Python falls back on
// copyreg._reduce_ex, which calls pybind11's base type to make the state: pybind11 cannot make
// an instance of it and aborts the process ("instance allocation failed: new instance has no
// pybind11-registered base types"). So every class defines __reduce__ (which pickle uses at
// every protocol): one of the two below, or its own (BinnedImage).
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <utility>

namespace pftrack::bind {

namespace py = pybind11;

/// __reduce__ of a class with py::pickle: ``copyreg.__newobj__(cls)``, then
/// ``__setstate__(__getstate__())``. What protocol 2 makes of it anyway (pickle writes it as
/// NEWOBJ there), and at protocols 0 and 1 the same steps by name.
inline py::tuple reduce_by_state(const py::object& self) {
    return py::make_tuple(py::module_::import("copyreg").attr("__newobj__"),
                          py::make_tuple(py::type::of(self)), self.attr("__getstate__")());
}

/// __reduce__ of a class that cannot be pickled: TypeError naming it and `why`, at every protocol
/// (and for copy.copy and copy.deepcopy, which reduce the object when it has no __copy__).
inline auto refuse_pickle(std::string name, std::string why) {
    return [name = std::move(name), why = std::move(why)](const py::object&) -> py::tuple {
        throw py::type_error("cannot pickle 'pftrack._core." + name + "' object: " + why);
    };
}

}  // namespace pftrack::bind
