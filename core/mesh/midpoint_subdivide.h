// One 1→4 midpoint subdivision: every edge split once at its midpoint (an edge's two faces share
// it), every triangle into four. Same shape, finer tessellation; boundary loops stay loops. New
// vertices follow the old ones, numbered in the order the faces first reach their edges. Used to
// make larger test and bench inputs from the bundled meshes.
#pragma once

#include "mesh/mesh.h"

namespace mm {

Mesh midpoint_subdivide(const Mesh& m);

}  // namespace mm
