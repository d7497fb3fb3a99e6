// (being written)
#include <pybind11/pybind11.h>
void bind_geometry(pybind11::module_&) {}
