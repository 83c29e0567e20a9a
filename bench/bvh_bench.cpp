// BVH build benchmark: loads a glTF scene, compiles it as candela render does, then
// builds its BVH again with each thread count, alternating, and prints one JSON line per
// build: seconds, triangles per second, SAH cost, depth, and whether the tree is
// byte-identical to the first count's; cpu_seconds: user + system time of the build
// (the builder promises the same tree for any count); digest: FNV-1a of the nodes and
// leaf triangles, to compare the trees of two builder versions.
//
// Usage: candela_bvh_bench SCENE.gltf [ROUNDS (3)] [THREADS,... (1,all)]
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "base/hash.hpp"
#include "compile/bvh_builder.hpp"
#include "compile/scene_compiler.hpp"
#include "gltf/gltf_loader.hpp"

using namespace candela;

static double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENE.gltf [ROUNDS] [THREADS,...]\n", argv[0]);
    return 1;
  }
  int rounds = argc > 2 ? std::atoi(argv[2]) : 3;
  std::vector<int> counts;
  if (argc > 3) {
    std::stringstream ss(argv[3]);
    for (std::string t; std::getline(ss, t, ',');)
      counts.push_back(t == "all" ? bvh_build_threads() : std::atoi(t.c_str()));
  } else {
    counts = {1, bvh_build_threads()};
  }
  try {
    CompiledScene c = compile_scene(load_gltf(argv[1]));
    std::vector<bool> alpha;  // the bench meshes have no alpha-tested materials
    const auto& pos = c.buffers.positions;
    const auto& prims = c.buffers.prims;
    Bvh first;
    bool have_first = false;
    for (int round = 0; round < rounds; ++round)
      for (int threads : counts) {
        double cpu0 = cpu_seconds();
        auto t0 = std::chrono::steady_clock::now();
        Bvh bvh = build_bvh(pos, prims, alpha, threads);
        double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        double cpu = cpu_seconds() - cpu0;
        bool same = true;
        if (!have_first) {
          first = bvh;
          have_first = true;
        } else {
          same = bvh.nodes.size() == first.nodes.size() && bvh.tris.size() == first.tris.size() &&
                 std::memcmp(bvh.nodes.data(), first.nodes.data(), bvh.nodes.size() * sizeof(bvh.nodes[0])) == 0 &&
                 std::memcmp(bvh.tris.data(), first.tris.data(), bvh.tris.size() * sizeof(bvh.tris[0])) == 0;
        }
        uint64_t digest = fnv1a64(
            std::string_view(reinterpret_cast<const char*>(bvh.tris.data()), bvh.tris.size() * sizeof(bvh.tris[0])),
            fnv1a64(std::string_view(reinterpret_cast<const char*>(bvh.nodes.data()),
                                     bvh.nodes.size() * sizeof(bvh.nodes[0]))));
        std::printf(
            "{\"scene\": \"%s\", \"triangles\": %zu, \"threads\": %d, \"round\": %d, \"seconds\": %.4f, "
            "\"cpu_seconds\": %.4f, "
            "\"triangles_per_second\": %.0f, \"sah_cost\": %.4f, \"depth\": %d, \"nodes\": %zu, "
            "\"same_tree\": %s, \"digest\": \"%016llx\"}\n",
            argv[1], prims.size(), threads, round, s, cpu, double(prims.size()) / s, sah_cost(bvh), bvh.depth,
            bvh.nodes.size(), same ? "true" : "false", (unsigned long long)digest);
        std::fflush(stdout);
      }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "candela_bvh_bench: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
