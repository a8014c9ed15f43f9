#include "tests/jitter.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>

#include "core/mesh/mesh_io.h"
#include "tests/fixtures.h"

namespace qs::test {

namespace {

// splitmix64: a well-mixed 64-bit value per (vertex, coordinate), the same on every machine.
uint64_t mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// A number in [-1, 1) from the top 53 bits of mix(key).
double unit(uint64_t key) {
  return static_cast<double>(mix(key) >> 11) * 0x1.0p-52 - 1.0;
}

template <class Mesh>
void jitter_mesh(Mesh& mesh) {
  const double scale = jitter_scale();
  if (scale == 0 || mesh.n_vertices() == 0) return;
  Vec3 lo = mesh.point(*mesh.vertices_begin()), hi = lo;
  for (auto v : mesh.vertices()) lo.minimize(mesh.point(v)), hi.maximize(mesh.point(v));
  const double step = scale * (hi - lo).norm();
  const uint64_t n = mesh.n_vertices();
  for (auto v : mesh.vertices()) {
    const uint64_t key = (n << 32) ^ (static_cast<uint64_t>(v.idx()) * 3);
    mesh.set_point(v, mesh.point(v) + step * Vec3(unit(key), unit(key + 1), unit(key + 2)));
  }
}

}  // namespace

double jitter_scale() {
  static const double scale = [] {
    const char* text = std::getenv("QS_TEST_JITTER");
    if (!text || !*text) return 0.0;
    char* end = nullptr;
    const double value = std::strtod(text, &end);
    if (*end != '\0' || !std::isfinite(value) || value < 0 || value > 1e-3) {
      std::fprintf(stderr, "QS_TEST_JITTER='%s': expected a number in [0, 1e-3]\n", text);
      std::abort();
    }
    return value;
  }();
  return scale;
}

void jitter(TriMesh& mesh) {
  jitter_mesh(mesh);
}

void jitter(PolyMesh& mesh) {
  jitter_mesh(mesh);
}

TriMesh load_mesh(const std::string& path) {
  TriMesh mesh = qs::load_mesh(path);
  jitter(mesh);
  return mesh;
}

PolyMesh load_poly_mesh(const std::string& path) {
  PolyMesh mesh = qs::load_poly_mesh(path);
  jitter(mesh);
  return mesh;
}

std::string mesh_file(const std::string& path) {
  if (jitter_scale() == 0) return path;
  static std::mutex mutex;
  static std::map<std::string, std::string> copies;  // one jittered copy per file and process
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = copies.find(path);
  if (it != copies.end()) return it->second;
  const std::string dir = temp_dir("jittered_" + std::to_string(copies.size()));
  const std::string copy =
      dir + "/" + std::filesystem::path(path).stem().string() + ".jittered.obj";
  write_obj(load_poly_mesh(path), copy);
  return copies.emplace(path, copy).first->second;
}

}  // namespace qs::test
