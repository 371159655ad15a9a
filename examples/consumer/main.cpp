// lift IN OUT: loads a mesh, prints its quality, lifts the region around its highest vertex with
// Remora's editor (the details ride along) and writes the result. Uses only the installed package.
#include <iostream>
#include <vector>

#include <remora/common/error.h>
#include <remora/geometry/measures.h>
#include <remora/geometry/quality.h>
#include <remora/geometry/selection.h>
#include <remora/linalg/solver.h>
#include <remora/mesh/io.h>
#include <remora/multires/editor.h>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: lift IN OUT\n";
    return 2;
  }
  try {
    const remora::LoadResult loaded = remora::read_mesh(argv[1]);
    const remora::Mesh& mesh = loaded.mesh;
    const remora::MeshQuality quality = remora::mesh_quality(mesh);
    std::cout << quality.vertices << " vertices, " << quality.faces << " faces, smallest angle "
              << quality.angles.min_deg << " degrees; solver " << remora::default_solver_name()
              << "\n";

    // The support: everything within 5 % of the bounding-box diagonal of the highest vertex;
    // the handle: within 1.5 %. The handle goes up by 2 %.
    remora::VertexHandle top = *mesh.vertices_begin();
    for (const remora::VertexHandle v : mesh.vertices())
      if (mesh.point(v)[1] > mesh.point(top)[1]) top = v;
    const double diagonal = remora::bounding_box_diagonal(mesh);
    const std::vector<int> support = remora::select_sphere(mesh, mesh.point(top), 0.05 * diagonal);
    const std::vector<int> handle = remora::select_sphere(mesh, mesh.point(top), 0.015 * diagonal);

    remora::Editor editor(mesh);
    editor.set_region(support, {handle});
    editor.set_transform(0, remora::translation(Eigen::Vector3d(0, 0.02 * diagonal, 0)));
    const remora::Mesh result = editor.result();
    remora::write_mesh(argv[2], result);

    const double lift = result.point(top)[1] - mesh.point(top)[1];
    std::cout << "support " << support.size() << " vertices, handle " << handle.size()
              << "; the top vertex rose by " << lift / diagonal << " of the diagonal\n";
    return lift > 0.01 * diagonal ? 0 : 1;
  } catch (const remora::Error& e) {
    std::cerr << "lift: " << e.what() << "\n";
    return 1;
  }
}
