// The smallest program using the installed qem library: load, simplify to 10 %, save.
#include <qem/qem.h>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 3) return std::fprintf(stderr, "usage: hello_qem IN OUT\n"), 2;
  qem::Mesh mesh = qem::load_mesh(argv[1]);
  qem::SimplifyOptions options;
  options.target_ratio = 0.1;
  qem::SimplifyResult result = qem::simplify(mesh, options);
  qem::save_mesh(argv[2], result.mesh);
  std::printf("%zu -> %zu faces, max error %g\n", mesh.face_count(), result.mesh.face_count(), result.max_error);
}
