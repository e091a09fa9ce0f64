#include "io/gltf_accessor.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace mm::io {

int gltf_component_count(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
  }
  return 0;
}

int gltf_component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
  }
  return 0;
}

namespace detail {

static double accessor_component(const uint8_t* p, int component_type, bool normalized) {
  // Little-endian storage (glTF) on little-endian hosts (x86-64, wasm32).
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v; std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v; std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v; std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v; std::memcpy(&v, p, 4);
      return normalized ? v / 4294967295.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v; std::memcpy(&v, p, 4);
      return v;
    }
  }
  return 0;
}

// Start of `count` elements of `elem_size` bytes at `stride` from `offset` in bufferView `bv`,
// or nullptr with *status set when any of it lies outside the buffer.
static const uint8_t* accessor_view_data(const tinygltf::Model& model, int bv, uint64_t offset, uint64_t count,
                                         uint64_t elem_size, uint64_t stride, const std::string& what,
                                         Status* status) {
  auto fail = [&](const std::string& why) {
    *status = Status::error(StatusCode::ParseError, what + ": " + why);
    return nullptr;
  };
  if (bv < 0 || bv >= static_cast<int>(model.bufferViews.size()))
    return fail("bufferView " + std::to_string(bv) + " does not exist");
  const tinygltf::BufferView& view = model.bufferViews[bv];
  if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size()))
    return fail("bufferView " + std::to_string(bv) + " refers to missing buffer " + std::to_string(view.buffer));
  const std::vector<unsigned char>& data = model.buffers[view.buffer].data;
  const uint64_t view_offset = view.byteOffset, view_length = view.byteLength;
  if (view_offset > data.size() || view_length > data.size() - view_offset)
    return fail("bufferView " + std::to_string(bv) + " (offset " + std::to_string(view.byteOffset) + ", length " +
                std::to_string(view.byteLength) + ") lies outside its buffer of " + std::to_string(data.size()) +
                " bytes");
  // offset + (count − 1)·stride + elem_size ≤ byteLength, without wrapping around (offsets near
  // 2^64 or huge counts must fail here, not read out of bounds).
  const bool overruns =
      count > 0 && (offset > view_length || elem_size > view_length - offset ||
                    (count - 1) > (view_length - offset - elem_size) / (stride > 0 ? stride : 1));
  if (overruns)
    return fail(std::to_string(count) + " elements of " + std::to_string(elem_size) + " bytes (stride " +
                std::to_string(stride) + ", offset " + std::to_string(offset) + ") overrun bufferView " +
                std::to_string(bv) + " of " + std::to_string(view.byteLength) + " bytes");
  return data.data() + view.byteOffset + offset;
}

}  // namespace detail

Status read_gltf_accessor(const tinygltf::Model& model, int index, Eigen::MatrixXd* out) {
  using namespace detail;
  const std::string what = "accessor " + std::to_string(index);
  if (index < 0 || index >= static_cast<int>(model.accessors.size()))
    return Status::error(StatusCode::ParseError, what + " does not exist");
  const tinygltf::Accessor& a = model.accessors[index];
  const int nc = gltf_component_count(a.type), cs = gltf_component_size(a.componentType);
  if (nc == 0 || cs == 0)
    return Status::error(StatusCode::ParseError, what + " has an unknown type or componentType");
  // A count above 2^31 cannot be backed by a GLB (4 GiB) with 2-byte elements; refuse it
  // before allocating.
  if (a.count > (size_t{1} << 31)) return Status::error(StatusCode::ParseError, what + " has an absurd count");
  const uint64_t count = a.count, elem = static_cast<uint64_t>(nc) * cs;
  Status status;
  // Bounds first, allocation second: a lying count must not allocate gigabytes.
  const uint8_t* p = nullptr;
  uint64_t stride = elem;
  if (a.bufferView >= 0) {
    const int stride_field = model.bufferViews.size() > static_cast<size_t>(a.bufferView)
                                 ? model.bufferViews[a.bufferView].byteStride
                                 : 0;
    stride = stride_field > 0 ? static_cast<uint64_t>(stride_field) : elem;
    if (stride < elem)
      return Status::error(StatusCode::ParseError, what + ": byteStride " + std::to_string(stride) +
                                                       " is smaller than the element size " + std::to_string(elem));
    p = accessor_view_data(model, a.bufferView, a.byteOffset, count, elem, stride, what, &status);
    if (!p) return status;
  } else if (count * static_cast<uint64_t>(nc) > (uint64_t{1} << 25)) {
    // Only sparse data backs an accessor without bufferView: its size is whatever the JSON claims,
    // so bound the zeros we allocate (2^25 values = 256 MiB of doubles; 11M VEC3 vertices). A
    // 200-byte file asking for 2^26 MAT4 elements allocated 8 GiB before this.
    return Status::error(StatusCode::ParseError, what + " has no bufferView and an implausible size (" +
                                                     std::to_string(count) + " elements of " + std::to_string(nc) +
                                                     " components; at most 33554432 values)");
  }
  out->setZero(static_cast<Eigen::Index>(count), nc);
  if (p)
    for (uint64_t i = 0; i < count; ++i)
      for (int c = 0; c < nc; ++c)
        (*out)(static_cast<Eigen::Index>(i), c) = accessor_component(p + i * stride + c * cs, a.componentType, a.normalized);
  if (a.sparse.isSparse) {
    const uint64_t n = static_cast<uint64_t>(std::max(a.sparse.count, 0));
    if (n > count) return Status::error(StatusCode::ParseError, what + ": sparse count exceeds the accessor count");
    const int ict = a.sparse.indices.componentType, ics = gltf_component_size(ict);
    if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      return Status::error(StatusCode::ParseError, what + ": sparse indices must be unsigned integers");
    const uint8_t* pi = accessor_view_data(model, a.sparse.indices.bufferView, a.sparse.indices.byteOffset, n, ics,
                                           ics, what + " sparse indices", &status);
    if (!pi) return status;
    const uint8_t* pv = accessor_view_data(model, a.sparse.values.bufferView, a.sparse.values.byteOffset, n, elem,
                                           elem, what + " sparse values", &status);
    if (!pv) return status;
    for (uint64_t k = 0; k < n; ++k) {
      const double target = accessor_component(pi + k * ics, ict, false);
      if (target >= static_cast<double>(count))
        return Status::error(StatusCode::ParseError, what + ": sparse index " + std::to_string(static_cast<uint64_t>(target)) +
                                                         " is beyond the accessor count " + std::to_string(count));
      for (int c = 0; c < nc; ++c)
        (*out)(static_cast<Eigen::Index>(target), c) = accessor_component(pv + k * elem + c * cs, a.componentType, a.normalized);
    }
  }
  return Status::success();
}

bool gltf_is_triangle_mode(int mode) {
  return mode == -1 || mode == TINYGLTF_MODE_TRIANGLES || mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
         mode == TINYGLTF_MODE_TRIANGLE_FAN;
}

Status read_gltf_triangles(const tinygltf::Model& model, const tinygltf::Primitive& prim, const std::string& label,
                           GltfTriangles* out) {
  auto fail = [&](const std::string& why) { return Status::error(StatusCode::ParseError, label + " " + why); };
  const auto pos_it = prim.attributes.find("POSITION");
  if (pos_it == prim.attributes.end()) return fail("has no POSITION attribute");
  Status s = read_gltf_accessor(model, pos_it->second, &out->P);
  if (!s.ok()) return Status::error(s.code, label + " POSITION: " + s.message);
  if (out->P.cols() != 3) return fail("POSITION is not VEC3");
  const int ct = model.accessors[pos_it->second].componentType;
  if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT) {
    bool quantized = false;
    for (const std::string& e : model.extensionsUsed) quantized |= e == "KHR_mesh_quantization";
    const bool quantizable = ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                             ct == TINYGLTF_COMPONENT_TYPE_SHORT || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    if (!quantized || !quantizable)
      return fail("POSITION has componentType " + std::to_string(ct) +
                  (quantizable ? " without the KHR_mesh_quantization extension" : "") + "; glTF requires FLOAT (5126)");
  }
  const int64_t nv = out->P.rows();
  std::vector<int64_t> I;
  if (prim.indices >= 0) {
    Eigen::MatrixXd idx;
    s = read_gltf_accessor(model, prim.indices, &idx);
    if (!s.ok()) return Status::error(s.code, label + " indices: " + s.message);
    const int ict = model.accessors[prim.indices].componentType;
    if (idx.cols() != 1 || (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                            ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
      return fail("indices must be unsigned integer scalars");
    I.resize(static_cast<size_t>(idx.rows()));
    for (Eigen::Index k = 0; k < idx.rows(); ++k) {
      if (idx(k, 0) >= static_cast<double>(nv))
        return fail("index " + std::to_string(k) + " is " + std::to_string(static_cast<long long>(idx(k, 0))) +
                    " but POSITION has only " + std::to_string(nv) + " vertices");
      I[static_cast<size_t>(k)] = static_cast<int64_t>(idx(k, 0));
    }
  } else {
    I.resize(static_cast<size_t>(nv));
    for (int64_t k = 0; k < nv; ++k) I[static_cast<size_t>(k)] = k;
  }
  const int64_t n = static_cast<int64_t>(I.size());
  std::vector<int64_t> T;
  if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP || prim.mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    if (n > 0 && n < 3) return fail("has " + std::to_string(n) + " vertices, too few for a triangle strip or fan");
    for (int64_t i = 0; i + 2 < n; ++i) {
      if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP)
        T.insert(T.end(), {I[i], I[i + 1 + i % 2], I[i + 2 - i % 2]});
      else
        T.insert(T.end(), {I[i + 1], I[i + 2], I[0]});
    }
  } else {
    if (n % 3 != 0) return fail("has " + std::to_string(n) + " indices, not a multiple of 3");
    T = std::move(I);
  }
  out->F.resize(static_cast<Eigen::Index>(T.size() / 3), 3);
  for (Eigen::Index f = 0; f < out->F.rows(); ++f)
    for (int k = 0; k < 3; ++k) out->F(f, k) = static_cast<int>(T[static_cast<size_t>(3 * f + k)]);
  return Status::success();
}

bool read_gltf_inverse_binds(const tinygltf::Model& model, const tinygltf::Skin& skin, Matrix4dList* out) {
  out->assign(skin.joints.size(), Eigen::Matrix4d::Identity());
  if (skin.inverseBindMatrices < 0) return true;
  Eigen::MatrixXd ib;
  if (!read_gltf_accessor(model, skin.inverseBindMatrices, &ib).ok() || ib.cols() != 16 ||
      ib.rows() < static_cast<Eigen::Index>(skin.joints.size()))
    return false;
  for (size_t j = 0; j < skin.joints.size(); ++j)
    for (int k = 0; k < 16; ++k) (*out)[j](k % 4, k / 4) = ib(static_cast<Eigen::Index>(j), k);  // column-major
  return true;
}

bool read_gltf_skin_influences(const tinygltf::Model& model, const tinygltf::Primitive& prim, Eigen::Index nv,
                               Eigen::MatrixXd* joints, Eigen::MatrixXd* weights) {
  joints->resize(nv, 0);
  weights->resize(nv, 0);
  for (int set = 0;; ++set) {
    const auto ja = prim.attributes.find("JOINTS_" + std::to_string(set));
    const auto wa = prim.attributes.find("WEIGHTS_" + std::to_string(set));
    if (ja == prim.attributes.end() || wa == prim.attributes.end()) return true;
    Eigen::MatrixXd j, w;
    if (!read_gltf_accessor(model, ja->second, &j).ok() || !read_gltf_accessor(model, wa->second, &w).ok() ||
        j.rows() != nv || w.rows() != nv || j.cols() != 4 || w.cols() != 4)
      return false;
    joints->conservativeResize(nv, 4 * (set + 1));
    weights->conservativeResize(nv, 4 * (set + 1));
    joints->rightCols<4>() = j;
    weights->rightCols<4>() = w;
  }
}

}  // namespace mm::io
