// What WebAssembly costs plain serial code, apart from anything MeshMorph does: three scalar
// kernels shaped like the core's serial stages, compiled from this one file by g++ -O3 (natively)
// and em++ -O3 (no SIMD flags), run under node (bench/scalar/run). Issue 18 asks every stage's wasm
// time to be ≤ 1.2× one native thread; these kernels show where that bound stands for code that
// neither threads nor SIMD reach (docs/bench.md, forty-third session).
//   spmv — CSR sparse matrix-vector products, 7 entries per row (a mesh Laplacian's pattern);
//   hash — welding-like: quantise points to cells and insert them in an open-addressing table;
//   tree — branchy stack traversal of a balanced tree of intervals (a BVH query's shape).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

uint64_t rng_state = 88172645463325252ull;
uint64_t next_random() {  // xorshift64: the same numbers on both targets
  rng_state ^= rng_state << 13;
  rng_state ^= rng_state >> 7;
  rng_state ^= rng_state << 17;
  return rng_state;
}

double spmv(int n, double* checksum) {
  std::vector<int> ptr(n + 1), col;
  std::vector<double> val, x(n, 1.0), y(n);
  for (int i = 0; i < n; ++i) {
    ptr[i] = static_cast<int>(col.size());
    for (int k = -3; k <= 3; ++k) {
      int j = i + k * 97;
      j = j < 0 ? j + n : j >= n ? j - n : j;
      col.push_back(j);
      val.push_back(1.0 / (1 + k * k));
    }
  }
  ptr[n] = static_cast<int>(col.size());
  const auto t = Clock::now();
  for (int r = 0; r < 50; ++r) {
    for (int i = 0; i < n; ++i) {
      double s = 0;
      for (int p = ptr[i]; p < ptr[i + 1]; ++p) s += val[p] * x[col[p]];
      y[i] = s;
    }
    x.swap(y);
  }
  *checksum = x[5];
  return ms_since(t);
}

double weld_hash(int n, double* checksum) {
  std::vector<double> P(3 * static_cast<size_t>(n));
  for (double& p : P) p = static_cast<double>(next_random() % 1000000) * 1e-6;
  const uint32_t mask = (1u << 21) - 1;
  std::vector<int64_t> keys(mask + 1);
  std::vector<int> slot(mask + 1);
  long hits = 0;
  const auto t = Clock::now();
  for (int r = 0; r < 10; ++r) {
    std::fill(keys.begin(), keys.end(), -1);
    for (int i = 0; i < n; ++i) {
      const int64_t a = static_cast<int64_t>(std::floor(P[3 * i] * 512));
      const int64_t b = static_cast<int64_t>(std::floor(P[3 * i + 1] * 512));
      const int64_t c = static_cast<int64_t>(std::floor(P[3 * i + 2] * 512));
      const int64_t key = (a * 73856093) ^ (b * 19349663) ^ (c * 83492791);
      uint32_t h = static_cast<uint32_t>((static_cast<uint64_t>(key) * 0x9E3779B97F4A7C15ull) >> 43);
      while (keys[h] != -1 && keys[h] != key) h = (h + 1) & mask;
      if (keys[h] == key) {
        ++hits;
      } else {
        keys[h] = key;
        slot[h] = i;
      }
    }
  }
  *checksum = static_cast<double>(hits);
  return ms_since(t);
}

double tree_queries(int queries, double* checksum) {
  const int nodes = (1 << 17) - 1, leaves_from = nodes / 2;
  std::vector<float> lo(nodes), hi(nodes);
  for (int i = nodes - 1; i >= 0; --i) {
    if (i >= leaves_from) {
      lo[i] = static_cast<float>(i - leaves_from) / static_cast<float>(leaves_from + 1) +
              static_cast<float>(next_random() % 100) * 1e-7f;
      hi[i] = lo[i] + 2e-5f;
    } else {
      lo[i] = std::min(lo[2 * i + 1], lo[2 * i + 2]);
      hi[i] = std::max(hi[2 * i + 1], hi[2 * i + 2]);
    }
  }
  long found = 0;
  const auto t = Clock::now();
  for (int q = 0; q < queries; ++q) {
    const float p = static_cast<float>(next_random() % 100000) * 1e-5f;
    int stack[64], top = 0;
    stack[top++] = 0;
    while (top) {
      const int i = stack[--top];
      if (p < lo[i] || p > hi[i]) continue;
      if (i >= leaves_from) {
        ++found;
        continue;
      }
      stack[top++] = 2 * i + 1;
      stack[top++] = 2 * i + 2;
    }
  }
  *checksum = static_cast<double>(found);
  return ms_since(t);
}

}  // namespace

int main() {
  double c1 = 0, c2 = 0, c3 = 0;
  const double t1 = spmv(400000, &c1), t2 = weld_hash(400000, &c2), t3 = tree_queries(200000, &c3);
  std::printf("spmv %.1f ms  hash %.1f ms  tree %.1f ms  (checksums %g %g %g)\n", t1, t2, t3, c1, c2, c3);
  return 0;
}
