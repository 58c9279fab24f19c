// OctoMap's update of the same scans, for python/bench_mapping.py (compiled there against
// Debian's liboctomap-dev). Reads the clouds file agrisim-mapping-bench wrote (per frame
// f32[3] origin, u32 n, n x f32[3] points in the map frame), inserts every frame with
// OcTree::insertPointCloud(cloud, origin, max_range) on a tree of the given resolution, times
// each insertion (best of `repeat` runs of the sequence on a fresh tree) and writes the final
// tree's known voxels at full depth (pruned nodes expanded) as u64 n, n x (i32 x, i32 y,
// i32 z, f32 log-odds), keys relative to the tree's centre (key - 32768), sorted.
//
// usage: octomap_bench CLOUDS RESOLUTION MAX_RANGE REPEAT MAP_OUT   (prints JSON)
#include <octomap/octomap.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <tuple>
#include <vector>

struct Scan {
  octomap::point3d origin;
  octomap::Pointcloud cloud;
};

int main(int argc, char** argv) {
  if (argc != 6) {
    std::cerr << "usage: octomap_bench CLOUDS RESOLUTION MAX_RANGE REPEAT MAP_OUT\n";
    return 2;
  }
  const double res = std::atof(argv[2]), max_range = std::atof(argv[3]);
  const int repeat = std::max(1, std::atoi(argv[4]));
  std::ifstream in(argv[1], std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) {
    std::cerr << "octomap_bench: cannot read " << argv[1] << "\n";
    return 1;
  }
  std::vector<Scan> scans;
  size_t at = 0;
  auto take = [&](void* dst, size_t n) {
    if (at + n > bytes.size()) return false;
    std::memcpy(dst, bytes.data() + at, n);
    at += n;
    return true;
  };
  while (at < bytes.size()) {
    float o[3];
    uint32_t n;
    if (!take(o, sizeof o) || !take(&n, 4)) {
      std::cerr << "octomap_bench: " << argv[1] << " truncated at byte " << at << "\n";
      return 1;
    }
    Scan s;
    s.origin = octomap::point3d(o[0], o[1], o[2]);
    s.cloud.reserve(n);
    for (uint32_t i = 0; i < n; ++i) {
      float p[3];
      if (!take(p, sizeof p)) {
        std::cerr << "octomap_bench: " << argv[1] << " truncated at byte " << at << "\n";
        return 1;
      }
      s.cloud.push_back(p[0], p[1], p[2]);
    }
    scans.push_back(std::move(s));
  }
  std::vector<double> best(scans.size(), std::numeric_limits<double>::infinity());
  octomap::OcTree* tree = nullptr;
  for (int r = 0; r < repeat; ++r) {
    delete tree;
    tree = new octomap::OcTree(res);
    for (size_t i = 0; i < scans.size(); ++i) {
      auto t0 = std::chrono::steady_clock::now();
      tree->insertPointCloud(scans[i].cloud, scans[i].origin, max_range, false, false);
      double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      best[i] = std::min(best[i], ms);
    }
  }
  std::vector<std::tuple<int32_t, int32_t, int32_t, float>> known;
  const unsigned depth = tree->getTreeDepth();
  for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
    const octomap::OcTreeKey k = it.getKey();
    const int span = 1 << (depth - it.getDepth());
    // A leaf above full depth covers span^3 voxels from its key with the low bits cleared.
    const int mask = ~(span - 1);
    for (int dz = 0; dz < span; ++dz)
      for (int dy = 0; dy < span; ++dy)
        for (int dx = 0; dx < span; ++dx)
          known.emplace_back((int32_t)((k[0] & mask) + dx) - 32768, (int32_t)((k[1] & mask) + dy) - 32768,
                             (int32_t)((k[2] & mask) + dz) - 32768, it->getLogOdds());
  }
  std::sort(known.begin(), known.end());
  std::ofstream out(argv[5], std::ios::binary);
  uint64_t n = known.size();
  out.write((const char*)&n, 8);
  for (auto& [x, y, z, l] : known) {
    out.write((const char*)&x, 4);
    out.write((const char*)&y, 4);
    out.write((const char*)&z, 4);
    out.write((const char*)&l, 4);
  }
  double total = 0;
  std::printf("{\"frames\": %zu, \"ms_per_frame\": [", scans.size());
  for (size_t i = 0; i < best.size(); ++i) {
    std::printf("%s%.3f", i ? ", " : "", best[i]);
    total += best[i];
  }
  std::printf("], \"mean_ms\": %.3f, \"known\": %zu}\n", scans.empty() ? 0.0 : total / scans.size(), known.size());
  delete tree;
  return 0;
}
