#include "clumpkit/raycast/mesh_solid.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "clumpkit/core/error.hpp"

namespace clumpkit {

std::uint64_t SplitMix::next() {
  std::uint64_t x = (state_ += 0x9E3779B97F4A7C15ull);
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

struct MeshSolid::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

struct Crossing {
  float t;
  unsigned prim;
};

// The intersect context carries the per-call list of crossings to the filter callback.
struct CollectContext {
  RTCIntersectContext base;
  std::vector<Crossing>* crossings;
};

// Records every candidate hit and rejects it, so traversal continues to the far end of the line.
void collect_all(const RTCFilterFunctionNArguments* args) {
  if (args->valid[0] == 0) return;
  auto* ctx = reinterpret_cast<CollectContext*>(args->context);
  ctx->crossings->push_back(
      {RTCRayN_tfar(args->ray, args->N, 0), RTCHitN_primID(args->hit, args->N, 0)});
  args->valid[0] = 0;
}

// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                    const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

struct PointQueryData {
  const TriangleMesh* mesh;
  Eigen::Vector3d p;
  double best2;
};

bool closest_triangle(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<PointQueryData*>(args->userPtr);
  const Eigen::Vector3i& t = q->mesh->triangles[args->primID];
  const Eigen::Vector3d& v = q->p;
  const Eigen::Vector3d c = closest_on_triangle(v, q->mesh->vertices[t[0]], q->mesh->vertices[t[1]],
                                                q->mesh->vertices[t[2]]);
  const double d2 = (c - v).squaredNorm();
  if (d2 < q->best2) {
    q->best2 = d2;
    // Shrink the search sphere, slightly generously: the query point is held in float.
    args->query->radius = static_cast<float>(std::sqrt(d2) * (1.0 + 1e-5)) + 1e-30f;
    return true;
  }
  return false;
}

}  // namespace

MeshSolid::MeshSolid(TriangleMesh mesh) : rtc_(std::make_unique<Embree>()), mesh_(std::move(mesh)) {
  if (mesh_.triangles.empty()) throw InputError("", "mesh", "empty mesh: no triangles");
  bounds_ = mesh_bounds(mesh_);
  offset_ = bounds_.center();
  merge_eps_ = 1e-6 * bounds_.diagonal().norm();
  normals_.reserve(mesh_.triangles.size());
  area_cdf_.reserve(mesh_.triangles.size());
  double area = 0.0;
  for (const Eigen::Vector3i& t : mesh_.triangles) {
    const Eigen::Vector3d& a = mesh_.vertices[t[0]];
    const Eigen::Vector3d n = (mesh_.vertices[t[1]] - a).cross(mesh_.vertices[t[2]] - a);
    const double len = n.norm();
    normals_.push_back(len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero());
    area += 0.5 * len;
    area_cdf_.push_back(area);
  }

  rtc_->device = rtcNewDevice(nullptr);
  if (!rtc_->device) throw std::runtime_error("Embree: cannot create a device");
  rtc_->scene = rtcNewScene(rtc_->device);
  // Robust mode: watertight traversal, so a line through a shared edge hits at least one side.
  rtcSetSceneFlags(rtc_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(rtc_->scene, RTC_BUILD_QUALITY_MEDIUM);
  RTCGeometry geom = rtcNewGeometry(rtc_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                         RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                         mesh_.vertices.size()));
  for (std::size_t i = 0; i < mesh_.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k)
      vb[3 * i + k] = static_cast<float>(mesh_.vertices[i][k] - offset_[k]);
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                                            RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                            mesh_.triangles.size()));
  for (std::size_t i = 0; i < mesh_.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) ib[3 * i + k] = static_cast<unsigned>(mesh_.triangles[i][k]);
  rtcSetGeometryIntersectFilterFunction(geom, collect_all);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(rtc_->scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(rtc_->scene);
  if (rtcGetDeviceError(rtc_->device) != RTC_ERROR_NONE)
    throw std::runtime_error("Embree: scene build failed");
}

MeshSolid::~MeshSolid() = default;

void MeshSolid::reset_counters() const {
  unresolved_ = 0;
  retried_ = 0;
}

bool MeshSolid::try_line(const Eigen::Vector3d& origin, int axis, IntervalList& out) const {
  thread_local std::vector<Crossing> crossings;
  crossings.clear();
  const double margin = 1e-3 * bounds_.diagonal().norm() + 1e-12;
  Eigen::Vector3f org = (origin - offset_).cast<float>();
  org[axis] = static_cast<float>(bounds_.min()[axis] - offset_[axis] - margin);
  const double org_axis = offset_[axis] + static_cast<double>(org[axis]);

  CollectContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.crossings = &crossings;
  RTCRayHit rh;
  rh.ray.org_x = org[0];
  rh.ray.org_y = org[1];
  rh.ray.org_z = org[2];
  rh.ray.dir_x = axis == 0 ? 1.f : 0.f;
  rh.ray.dir_y = axis == 1 ? 1.f : 0.f;
  rh.ray.dir_z = axis == 2 ? 1.f : 0.f;
  rh.ray.tnear = 0.f;
  rh.ray.tfar = static_cast<float>(bounds_.sizes()[axis] + 2.0 * margin) * 1.001f;
  rh.ray.time = 0.f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(rtc_->scene, &ctx.base, &rh);

  out.clear();
  if (crossings.empty()) return true;
  std::sort(crossings.begin(), crossings.end(), [](const Crossing& a, const Crossing& b) {
    return a.t < b.t || (a.t == b.t && a.prim < b.prim);
  });
  // A triangle can be reported twice (it may sit in two BVH leaves): keep one.
  crossings.erase(
      std::unique(crossings.begin(), crossings.end(),
                  [](const Crossing& a, const Crossing& b) { return a.prim == b.prim; }),
      crossings.end());
  // Walk clusters of near-coincident crossings. Within a cluster the net direction decides:
  // all entering (a line through an edge between two front faces) is one entry; one entering and
  // one leaving (a graze along a silhouette edge) is nothing.
  int winding = 0;
  double start = 0.0;
  std::size_t i = 0;
  while (i < crossings.size()) {
    std::size_t j = i;
    int net = 0;
    double tsum = 0.0;
    while (j < crossings.size() &&
           static_cast<double>(crossings[j].t) - static_cast<double>(crossings[i].t) <=
               merge_eps_) {
      const double n = normals_[crossings[j].prim][axis];
      net += n < 0 ? 1 : (n > 0 ? -1 : 0);
      tsum += static_cast<double>(crossings[j].t);
      ++j;
    }
    const double t = org_axis + tsum / static_cast<double>(j - i);
    const int step = net > 0 ? 1 : (net < 0 ? -1 : 0);
    if (step > 0) {
      if (winding == 0) start = t;
      ++winding;
    } else if (step < 0) {
      if (--winding < 0) return false;
      if (winding == 0 && t > start) out.push_back({start, t});
    }
    i = j;
  }
  return winding == 0;
}

void MeshSolid::intervals(const Eigen::Vector3d& origin, int axis, IntervalList& out) const {
  if (try_line(origin, axis, out)) return;
  // An ambiguous line (through a vertex or along an edge, where float arithmetic disagrees with
  // itself): shift it sideways by a negligible amount and try again.
  ++retried_;
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const double h = 1e-6 * bounds_.diagonal().norm();
  const double shifts[3][2] = {{h, 0.37 * h}, {-0.61 * h, h}, {0.29 * h, -0.83 * h}};
  for (const auto& s : shifts) {
    Eigen::Vector3d o = origin;
    o[u] += s[0];
    o[v] += s[1];
    if (try_line(o, axis, out)) return;
  }
  ++unresolved_;
  out.clear();
}

double MeshSolid::surface_distance(const Eigen::Vector3d& p) const {
  PointQueryData data{&mesh_, p, std::numeric_limits<double>::infinity()};
  RTCPointQuery q;
  const Eigen::Vector3f pf = (p - offset_).cast<float>();
  q.x = pf[0];
  q.y = pf[1];
  q.z = pf[2];
  q.time = 0.f;
  q.radius = std::numeric_limits<float>::infinity();
  RTCPointQueryContext ctx;
  rtcInitPointQueryContext(&ctx);
  rtcPointQuery(rtc_->scene, &q, &ctx, closest_triangle, &data);
  return std::sqrt(data.best2);
}

std::vector<Eigen::Vector3d> MeshSolid::sample_surface(std::size_t n, std::uint64_t seed) const {
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(n);
  SplitMix rng(seed);
  const double total = area_cdf_.back();
  for (std::size_t k = 0; k < n; ++k) {
    const double a = rng.uniform() * total;
    const std::size_t f = std::min<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(area_cdf_.begin(), area_cdf_.end(), a) -
                                 area_cdf_.begin()),
        area_cdf_.size() - 1);
    const Eigen::Vector3i& t = mesh_.triangles[f];
    const double s = std::sqrt(rng.uniform()), r = rng.uniform();
    pts.push_back((1 - s) * mesh_.vertices[t[0]] + s * (1 - r) * mesh_.vertices[t[1]] +
                  s * r * mesh_.vertices[t[2]]);
  }
  return pts;
}

}  // namespace clumpkit
