// (being written)
#include <pybind11/pybind11.h>
void bind_contact(pybind11::module_&) {}
