// The half-edge mesh every Remora algorithm works on: OpenMesh's array-kernel triangle mesh with
// double-precision points. Status attributes are on so that algorithms can delete elements and
// garbage-collect; normals are not stored (algorithms compute what they need).
#pragma once

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

namespace remora {

struct MeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge | OpenMesh::Attributes::Status);
};

using Mesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;
using Vec3 = OpenMesh::Vec3d;
using VertexHandle = OpenMesh::VertexHandle;
using FaceHandle = OpenMesh::FaceHandle;
using EdgeHandle = OpenMesh::EdgeHandle;
using HalfedgeHandle = OpenMesh::HalfedgeHandle;

/// A face counts as zero-area when its area <= kZeroAreaRelative * (bounding-box diagonal)^2.
inline constexpr double kZeroAreaRelative = 1e-12;

} // namespace remora
