#include "io/gltf_builder.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace mm::io {

int gltf_append_view(tinygltf::Model* model, int buffer, const uint8_t* data, size_t size, int target) {
  std::vector<unsigned char>& b = model->buffers[buffer].data;
  // 4-byte alignment covers every component type; GLB chunks need it too.
  b.resize((b.size() + 3) / 4 * 4, 0);
  tinygltf::BufferView view;
  view.buffer = buffer;
  view.byteOffset = b.size();
  view.byteLength = size;
  view.target = target;
  b.insert(b.end(), data, data + size);
  model->bufferViews.push_back(view);
  return static_cast<int>(model->bufferViews.size()) - 1;
}

int gltf_append_float_accessor(tinygltf::Model* model, int buffer, const Eigen::MatrixXd& M, bool with_min_max) {
  const int nc = static_cast<int>(M.cols());
  assert((nc == 2 || nc == 3 || nc == 4) && "VEC2..VEC4 only");
  std::vector<float> f(static_cast<size_t>(M.rows()) * nc);
  for (Eigen::Index r = 0; r < M.rows(); ++r)
    for (int c = 0; c < nc; ++c) f[r * nc + c] = static_cast<float>(M(r, c));
  tinygltf::Accessor a;
  a.bufferView = gltf_append_view(model, buffer, reinterpret_cast<const uint8_t*>(f.data()), f.size() * sizeof(float),
                                  TINYGLTF_TARGET_ARRAY_BUFFER);
  a.byteOffset = 0;
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.count = static_cast<size_t>(M.rows());
  a.type = nc == 2 ? TINYGLTF_TYPE_VEC2 : nc == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4;
  if (with_min_max && M.rows() > 0) {
    // The validator compares min/max with the stored floats exactly, so take them from f.
    a.minValues.assign(nc, 0);
    a.maxValues.assign(nc, 0);
    for (int c = 0; c < nc; ++c) {
      float lo = f[c], hi = f[c];
      for (Eigen::Index r = 1; r < M.rows(); ++r) {
        lo = std::min(lo, f[r * nc + c]);
        hi = std::max(hi, f[r * nc + c]);
      }
      a.minValues[c] = lo;
      a.maxValues[c] = hi;
    }
  }
  model->accessors.push_back(a);
  return static_cast<int>(model->accessors.size()) - 1;
}

int gltf_append_short_vec3_accessor(tinygltf::Model* model, int buffer, const Eigen::MatrixXd& Q) {
  assert(Q.cols() == 3 && "VEC3 only");
  std::vector<int16_t> s(static_cast<size_t>(Q.rows()) * 4, 0);  // x, y, z, padding
  for (Eigen::Index r = 0; r < Q.rows(); ++r)
    for (int c = 0; c < 3; ++c) {
      assert(Q(r, c) == std::round(Q(r, c)) && std::abs(Q(r, c)) <= 32767 && "integers of SHORT range");
      s[r * 4 + c] = static_cast<int16_t>(Q(r, c));
    }
  tinygltf::Accessor a;
  a.bufferView = gltf_append_view(model, buffer, reinterpret_cast<const uint8_t*>(s.data()), s.size() * sizeof(int16_t),
                                  TINYGLTF_TARGET_ARRAY_BUFFER);
  model->bufferViews[a.bufferView].byteStride = 8;
  a.componentType = TINYGLTF_COMPONENT_TYPE_SHORT;
  a.normalized = false;
  a.count = static_cast<size_t>(Q.rows());
  a.type = TINYGLTF_TYPE_VEC3;
  if (Q.rows() > 0) {
    a.minValues.assign(3, 0);
    a.maxValues.assign(3, 0);
    for (int c = 0; c < 3; ++c) {
      a.minValues[c] = Q.col(c).minCoeff();
      a.maxValues[c] = Q.col(c).maxCoeff();
    }
  }
  model->accessors.push_back(a);
  return static_cast<int>(model->accessors.size()) - 1;
}

int gltf_append_index_accessor(tinygltf::Model* model, int buffer, const Eigen::MatrixXi& F) {
  const Eigen::Index w = F.cols();
  std::vector<uint32_t> idx(static_cast<size_t>(F.rows()) * w);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (Eigen::Index c = 0; c < w; ++c) idx[f * w + c] = static_cast<uint32_t>(F(f, c));
  tinygltf::Accessor a;
  a.bufferView = gltf_append_view(model, buffer, reinterpret_cast<const uint8_t*>(idx.data()),
                                  idx.size() * sizeof(uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  a.count = idx.size();
  a.type = TINYGLTF_TYPE_SCALAR;
  model->accessors.push_back(a);
  return static_cast<int>(model->accessors.size()) - 1;
}

}  // namespace mm::io
