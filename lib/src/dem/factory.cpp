// Factories: random, non-overlapping insertion of clumps into box (optionally cut by planes) or
// cylinder regions.
#include "clumpkit/dem/factory.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <unordered_map>

#include "clumpkit/core/error.hpp"
#include "dem/world_impl.hpp"

namespace clumpkit::dem {

bool region_contains(const Region& r, const Eigen::Vector3d& p, double margin) {
  if (const auto* b = std::get_if<BoxRegion>(&r)) {
    if ((p.array() - b->min.array() < margin).any() || (b->max.array() - p.array() < margin).any())
      return false;
    for (const HalfSpace& h : b->cuts)
      if ((p - h.point).dot(h.normal) < margin) return false;
    return true;
  }
  const auto& c = std::get<CylinderRegion>(r);
  const Eigen::Vector3d d = p - c.base_center;
  return d.z() >= margin && c.height - d.z() >= margin && c.radius - d.head<2>().norm() >= margin;
}

double region_volume(const Region& r) {
  if (const auto* b = std::get_if<BoxRegion>(&r)) {
    const Eigen::Vector3d size = b->max - b->min;
    if (b->cuts.empty()) return size.prod();
    const int n = 64;
    long in = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          const Eigen::Vector3d f((i + 0.5) / n, (j + 0.5) / n, (k + 0.5) / n);
          in += region_contains(r, b->min + size.cwiseProduct(f)) ? 1 : 0;
        }
    return size.prod() * double(in) / double(n * n * n);
  }
  const auto& c = std::get<CylinderRegion>(r);
  return std::numbers::pi * c.radius * c.radius * c.height;
}

std::string describe(const Region& r) {
  char buf[160];
  if (const auto* b = std::get_if<BoxRegion>(&r)) {
    const Eigen::Vector3d d = (b->max - b->min) * 1e3;
    std::snprintf(buf, sizeof buf, "box %.4g x %.4g x %.4g mm", d.x(), d.y(), d.z());
    const size_t n = b->cuts.size();
    if (n > 0)
      return buf +
             (n == 1 ? std::string(" cut by a plane") : " cut by " + std::to_string(n) + " planes");
  } else {
    const auto& c = std::get<CylinderRegion>(r);
    std::snprintf(buf, sizeof buf, "cylinder D %.4g mm x H %.4g mm", 2e3 * c.radius,
                  1e3 * c.height);
  }
  return buf;
}

namespace {

double uniform(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);
}

// Uniformly distributed rotation (Shoemake 1992).
Eigen::Quaterniond random_rotation(std::mt19937_64& rng) {
  const double u1 = uniform(rng), u2 = uniform(rng), u3 = uniform(rng);
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const double t2 = 2.0 * std::numbers::pi * u2, t3 = 2.0 * std::numbers::pi * u3;
  return Eigen::Quaterniond(b * std::cos(t3), a * std::sin(t2), a * std::cos(t2), b * std::sin(t3));
}

// A centre of mass at which a clump of bounding radius `bound` lies inside the region (0: a
// centre anywhere in it). A box's cuts are met by rejection: none when 32 draws in a row fall
// beyond a cut (the attempt then counts as failed).
std::optional<Eigen::Vector3d> random_point(const Region& region, double bound,
                                            std::mt19937_64& rng) {
  if (const auto* b = std::get_if<BoxRegion>(&region)) {
    for (int draw = 0; draw < 32; ++draw) {
      Eigen::Vector3d p;
      for (int k = 0; k < 3; ++k) {
        const double lo = b->min[k] + bound, hi = b->max[k] - bound;
        p[k] = lo + (hi - lo) * uniform(rng);
      }
      bool in = true;
      for (const HalfSpace& h : b->cuts) in = in && (p - h.point).dot(h.normal) >= bound;
      if (in) return p;
    }
    return std::nullopt;
  }
  const auto& c = std::get<CylinderRegion>(region);
  const double rr = std::max(0.0, c.radius - bound);
  const double rad = rr * std::sqrt(uniform(rng));
  const double ang = 2.0 * std::numbers::pi * uniform(rng);
  const double z = bound + (c.height - 2.0 * bound) * uniform(rng);
  return c.base_center + Eigen::Vector3d(rad * std::cos(ang), rad * std::sin(ang), z);
}

// Spheres near the region, hashed by cell, for overlap tests during a batch.
struct PlacementGrid {
  double cell;
  std::unordered_map<std::uint64_t, std::vector<int>> cells;
  std::vector<Eigen::Vector3d> pos;
  std::vector<double> rad;
  static std::uint64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    const std::int64_t b = 1 << 20;
    return (std::uint64_t(x + b) << 42) | (std::uint64_t(y + b) << 21) | std::uint64_t(z + b);
  }
  std::int64_t c(double v) const { return static_cast<std::int64_t>(std::floor(v / cell)); }
  void add(const Eigen::Vector3d& p, double r) {
    cells[key(c(p.x()), c(p.y()), c(p.z()))].push_back(static_cast<int>(pos.size()));
    pos.push_back(p);
    rad.push_back(r);
  }
  bool overlaps(const Eigen::Vector3d& p, double r) const {
    const std::int64_t x = c(p.x()), y = c(p.y()), z = c(p.z());
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = cells.find(key(x + dx, y + dy, z + dz));
          if (it == cells.end()) continue;
          for (int k : it->second) {
            const double rr = r + rad[k];
            if ((pos[k] - p).squaredNorm() < rr * rr) return true;
          }
        }
    return false;
  }
};

}  // namespace

void World::Impl::run_factories() {
  for (size_t fi = 0; fi < factories.size(); ++fi) {
    FactoryRuntime& f = factories[fi];
    if (f.status.done || time < f.s.start_time - 1e-12) continue;
    const bool at_once = f.s.rate == 0.0;
    const Region& region = f.s.region;
    if (f.interval == 0.0) {
      double height = 0.0;
      if (const auto* b = std::get_if<BoxRegion>(&region))
        height = b->max.z() - b->min.z();
      else
        height = std::get<CylinderRegion>(region).height;
      const double g = std::max(settings.gravity.norm(), 1e-9);
      f.interval = f.s.interval > 0.0 ? f.s.interval : std::sqrt(2.0 * height / g);
    }
    const double batch_time = f.s.start_time + f.batch * f.interval;
    if (!at_once && time < batch_time - 1e-12) continue;

    // What is due by the end of this batch.
    double due = 0.0;
    const bool by_count = f.s.count.has_value();
    const double target = by_count ? static_cast<double>(*f.s.count) : *f.s.mass;
    due = at_once ? target : std::min(target, f.s.rate * f.interval * (f.batch + 1));
    ++f.batch;
    const double had = by_count ? static_cast<double>(f.status.inserted) : f.status.inserted_mass;

    // Overlap grid: existing spheres near the region, plus wall triangles near it.
    Eigen::AlignedBox3d box;
    if (const auto* b = std::get_if<BoxRegion>(&region)) {
      box = Eigen::AlignedBox3d(b->min, b->max);
    } else {
      const auto& c = std::get<CylinderRegion>(region);
      box = Eigen::AlignedBox3d(c.base_center - Eigen::Vector3d(c.radius, c.radius, 0.0),
                                c.base_center + Eigen::Vector3d(c.radius, c.radius, c.height));
    }
    // Clumps whose centre only is in the region reach out of it by up to their bounding radius.
    double reach = 0.0;
    if (!f.s.whole_in_region)
      for (int t : f.types) reach = std::max(reach, types[t].bound_radius);
    PlacementGrid grid{std::max(2.0 * r_max, 1e-9), {}, {}, {}};
    Eigen::AlignedBox3d grown = box;
    grown.min().array() -= 2.0 * r_max + reach;
    grown.max().array() += 2.0 * r_max + reach;
    for (size_t s = 0; s < s_pos.size(); ++s)
      if (grown.contains(s_pos[s])) grid.add(s_pos[s], s_r[s]);
    std::vector<std::array<Eigen::Vector3d, 3>> tris;
    for (const WallData& wd : walls)
      for (const auto& t : wd.triangles) {
        Eigen::AlignedBox3d tb(wd.vertices[t[0]]);
        tb.extend(wd.vertices[t[1]]);
        tb.extend(wd.vertices[t[2]]);
        if (tb.intersects(grown))
          tris.push_back({wd.vertices[t[0]], wd.vertices[t[1]], wd.vertices[t[2]]});
      }

    const int first_new = static_cast<int>(c_x.size());
    double batch_energy = 0.0;
    long placed = 0;
    bool stuck = false, reached = false;
    while (true) {
      const double have =
          by_count ? static_cast<double>(f.status.inserted) : f.status.inserted_mass;
      // Mixture: the entry furthest below its mass share gets the next clump.
      int pick = 0;
      double best = -std::numeric_limits<double>::infinity();
      for (size_t e = 0; e < f.types.size(); ++e) {
        const double deficit =
            f.fractions[e] * (f.status.inserted_mass + types[f.types[e]].mass) - f.type_mass[e];
        if (deficit > best) best = deficit, pick = static_cast<int>(e);
      }
      const int type = f.types[pick];
      const TypeData& td = types[type];
      if (by_count ? have >= due : have + 0.5 * td.mass >= due) {
        reached = true;
        break;
      }
      bool ok = false;
      for (int attempt = 0; attempt < f.s.attempts_per_clump && !ok; ++attempt) {
        const std::optional<Eigen::Vector3d> xo =
            random_point(region, f.s.whole_in_region ? td.bound_radius : 0.0, f.rng);
        if (!xo) {
          ++f.status.failed_attempts;
          continue;
        }
        const Eigen::Vector3d x = *xo;
        const Eigen::Quaterniond q =
            f.s.random_orientation ? random_rotation(f.rng) : Eigen::Quaterniond::Identity();
        const Eigen::Matrix3d R = q.toRotationMatrix();
        ok = true;
        for (size_t k = 0; k < td.radii.size() && ok; ++k) {
          const Eigen::Vector3d p = x + R * td.offsets[k];
          if (grid.overlaps(p, td.radii[k])) ok = false;
          for (const auto& t : tris) {
            if (!ok) break;
            const Eigen::Vector3d c = closest_point_on_triangle(p, t[0], t[1], t[2]);
            if ((c - p).squaredNorm() < td.radii[k] * td.radii[k]) ok = false;
          }
        }
        if (!ok) {
          ++f.status.failed_attempts;
          continue;
        }
        for (size_t k = 0; k < td.radii.size(); ++k) grid.add(x + R * td.offsets[k], td.radii[k]);
        add_clump(type, x, q, f.s.velocity, Eigen::Vector3d::Zero());
        batch_energy +=
            0.5 * td.mass * f.s.velocity.squaredNorm() - td.mass * settings.gravity.dot(x);
        ++f.status.inserted;
        f.status.inserted_mass += td.mass;
        f.type_mass[pick] += td.mass;
        ++placed;
      }
      if (!ok) {
        stuck = true;
        break;
      }
    }
    inserted_energy += batch_energy;
    if (placed > 0) update_spheres(first_new);
    const double have = by_count ? static_cast<double>(f.status.inserted) : f.status.inserted_mass;
    const std::string unit = by_count ? " clumps" : " kg";
    if (stuck && at_once)
      throw InputError(settings.source, "factories[" + std::to_string(fi) + "].region",
                       "factory '" + f.s.name + "' could place only " + fmt_g(have) + " of " +
                           fmt_g(target) + unit + " in its region (" + describe(region) +
                           ", volume " + fmt_g(region_volume(region) * 1e6) + " cm^3) after " +
                           std::to_string(f.s.attempts_per_clump) +
                           " random tries per clump; enlarge the region, ask for less, or "
                           "insert at a rate");
    if (stuck && f.s.fail_if_behind && due - have > 2.0 * f.s.rate * f.interval)
      throw InputError(settings.source, "factories[" + std::to_string(fi) + "].rate",
                       "factory '" + f.s.name + "' falls behind: " + fmt_g(due - have) + unit +
                           " could not be placed in its region (" + describe(region) +
                           ") by t = " + fmt_g(time) +
                           " s; the region stays full; lower the rate or enlarge the region");
    // A factory allowed to fall behind whose region is blocked (nothing fitted in this batch,
    // e.g. the heap has grown into it) is finished: waiting would never end.
    if (stuck && !f.s.fail_if_behind && placed == 0) f.status.done = true;
    // ... and so is one whose blocked region only trickles (end_below).
    if (stuck && !f.s.fail_if_behind && !at_once &&
        have - had < f.s.end_below * f.s.rate * f.interval)
      f.status.done = true;
    if ((reached && due >= target) || at_once) f.status.done = true;
  }
}

}  // namespace clumpkit::dem
