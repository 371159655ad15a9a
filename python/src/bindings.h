// The parts of the compiled module remora._remora, one per file; module.cpp calls them.
#pragma once

#include <pybind11/pybind11.h>

#include "convert.h"
#include "remora/remesh/remesh.h"

namespace remora::python {

void bind_mesh(py::module_& m);    // bind_mesh.cpp: files, repair, quality, selections
void bind_remesh(py::module_& m);  // bind_remesh.cpp: remesh, the base surface's low-pass filter
void bind_editor(py::module_& m);  // bind_editor.cpp: the Editor, handle transforms
void bind_systems(py::module_& m); // bind_systems.cpp: Laplacian, mass, k-harmonic system

/// RemeshOptions by keyword (the field names; "equalization" and "smoothing_target" by name,
/// "lambda_" for lambda): shared by remesh() and the Editor's remesh_options.
const OptionSetters<RemeshOptions>& remesh_setters();

} // namespace remora::python
