#include "clumpkit/dem/contact_law.hpp"

#include <cmath>
#include <numbers>

#include "clumpkit/core/error.hpp"

namespace clumpkit::dem {

const char* to_string(RollingModel m) {
  switch (m) {
    case RollingModel::kStandard:
      return "standard";
    case RollingModel::kStandardCom:
      return "standard_com";
    case RollingModel::kCdt:
      return "cdt";
    case RollingModel::kEpsd:
      return "epsd";
  }
  return "?";
}

RollingModel rolling_model_from_string(const std::string& s, const std::string& where,
                                       const std::string& field) {
  if (s == "standard") return RollingModel::kStandard;
  if (s == "standard_com") return RollingModel::kStandardCom;
  if (s == "cdt") return RollingModel::kCdt;
  if (s == "epsd") return RollingModel::kEpsd;
  throw InputError(where, field,
                   "unknown rolling model '" + s + "' (known: standard, standard_com, cdt, epsd)");
}

PairContact PairContact::from(const Interaction& i, RollingModel model) {
  PairContact p;
  p.restitution = i.restitution;
  p.static_friction = i.static_friction;
  RollingFriction r;
  r.model = model;
  r.coefficient = i.rolling_friction;
  p.rolling = r;
  return p;
}

void PairContact::validate(const std::string& where, const std::string& field) const {
  auto bad = [&](const std::string& f, double v, const std::string& rule) {
    throw InputError(where, field + "." + f,
                     "value " + std::to_string(v) + " is out of range: " + rule);
  };
  if (restitution && !(*restitution > 0.0 && *restitution <= 1.0))
    bad("restitution", *restitution, "e must lie in (0, 1]");
  if (static_friction && !(*static_friction >= 0.0 && std::isfinite(*static_friction)))
    bad("static_friction", *static_friction, "must be >= 0");
  if (rolling) {
    if (!(rolling->coefficient >= 0.0 && std::isfinite(rolling->coefficient)))
      bad("rolling_friction", rolling->coefficient, "must be >= 0");
    if (!(rolling->viscous_damping >= 0.0 && std::isfinite(rolling->viscous_damping)))
      bad("rolling_viscous_damping", rolling->viscous_damping, "must be >= 0");
  }
  if (cohesion && !(cohesion->energy_density >= 0.0 && std::isfinite(cohesion->energy_density)))
    bad("cohesion_energy_density", cohesion->energy_density, "must be >= 0 J/m^3");
}

ResolvedContact resolve(const Material& a, const Material& b, const PairContact& law) {
  ResolvedContact r;
  r.e_star = 1.0 / ((1.0 - a.poisson_ratio * a.poisson_ratio) / a.youngs_modulus +
                    (1.0 - b.poisson_ratio * b.poisson_ratio) / b.youngs_modulus);
  r.g_star = 1.0 / (2.0 * (2.0 - a.poisson_ratio) * (1.0 + a.poisson_ratio) / a.youngs_modulus +
                    2.0 * (2.0 - b.poisson_ratio) * (1.0 + b.poisson_ratio) / b.youngs_modulus);
  if (law.restitution) {
    r.damping = true;
    const double l = std::log(*law.restitution);
    r.beta = -l / std::sqrt(l * l + std::numbers::pi * std::numbers::pi);
  }
  if (law.static_friction) {
    r.friction = true;
    r.mu_s = *law.static_friction;
  }
  if (law.rolling) {
    r.rolling = true;
    r.roll = *law.rolling;
  }
  if (law.cohesion) {
    r.cohesion = true;
    r.cohesion_k = law.cohesion->energy_density;
  }
  return r;
}

Eigen::Vector3d project_to_tangent(const Eigen::Vector3d& v, const Eigen::Vector3d& n) {
  const double len2 = v.squaredNorm();
  if (len2 == 0.0) return v;
  Eigen::Vector3d t = v - v.dot(n) * n;
  const double t2 = t.squaredNorm();
  if (t2 == 0.0) return Eigen::Vector3d::Zero();
  // The contact plane turned: keep the spring's length, drop its normal component.
  return t * std::sqrt(len2 / t2);
}

void evaluate_contact(const ResolvedContact& law, const ContactKinematics& k, double dt,
                      ContactHistory& h, ContactForce& out) {
  const Eigen::Vector3d& n = k.normal;
  const double delta = k.overlap;
  out.torque_i.setZero();
  out.torque_j.setZero();
  out.roll_i = out.roll_j = 0.0;
  out.elastic_energy = 0.0;
  out.dashpot_n = out.dashpot_t = 0.0;
  if (!(delta > 0.0)) {
    // Closing contact: the overlap ended during the step; only the damping impulse that
    // belongs to the part of the window before the separation is left.
    const double fn = dt > 0.0 ? -h.damping / dt : 0.0;
    out.force = fn * n;
    out.normal = fn;
    if (dt > 0.0) h = ContactHistory{};
    return;
  }
  const double sqrt_rd = std::sqrt(k.r_star * delta);
  // Normal: Hertz spring plus the paper's damping, eq. (3).
  const double sn = 2.0 * law.e_star * sqrt_rd;
  const double f_hertz = (4.0 / 3.0) * law.e_star * sqrt_rd * delta;
  const double vn = k.v_rel.dot(n);
  const Eigen::Vector3d& vd = k.v_rel_damping ? *k.v_rel_damping : k.v_rel;
  const double vdn = vd.dot(n);
  double fn = f_hertz;
  if (law.damping) {
    // c δ^(1/4) δ̇ = dΦ/dt, Φ(δ) = (4/5) c δ^(5/4); δ̇ = −vdn.
    const double c = normal_dashpot_constant(law, k.r_star, k.m_star);
    out.dashpot_n = c * std::sqrt(std::sqrt(delta));
    if (dt > 0.0) {
      const double d_up = delta - 0.5 * dt * vdn;
      const double phi_up = d_up > 0.0 ? 0.8 * c * d_up * std::sqrt(std::sqrt(d_up)) : 0.0;
      fn += (phi_up - h.damping) / dt;
      h.damping = phi_up;
    } else {
      fn -= c * std::sqrt(std::sqrt(delta)) * vdn;
    }
  } else {
    h.damping = 0.0;
  }
  const double fn_contact = fn;  // Coulomb and rolling limits use the contact force
  out.elastic_energy = 0.4 * f_hertz * delta;
  if (law.cohesion) {
    fn -= law.cohesion_k * 2.0 * std::numbers::pi * k.r_star * delta;
    // Its potential, −k π R* δ², so the energy balance of the blow-up check stays closed.
    out.elastic_energy -= law.cohesion_k * std::numbers::pi * k.r_star * delta * delta;
  }
  out.force = fn * n;
  out.normal = fn;

  // Tangential: Mindlin no-slip history spring with damping, capped at μs |Fn|, eq. (4).
  if (law.friction) {
    const double st = 8.0 * law.g_star * sqrt_rd;
    const Eigen::Vector3d vt = k.v_rel - vn * n;
    h.shear = project_to_tangent(h.shear, n) + vt * dt;
    Eigen::Vector3d ft = -st * h.shear;
    // As LIGGGHTS 3.8 (tangential_model_history): the spring alone is compared with the
    // Coulomb limit. Sliding: the spring is cut back to the cone and carries the whole force,
    // without damping. Sticking: spring plus damping. Putting the damping force into the
    // rescaled spring instead would store energy no force paid for (a jammed pill then gains
    // energy every step).
    const double cap = law.mu_s * std::abs(fn_contact);
    // Squared lengths compared: the square root only for a sliding contact.
    const double fs2 = ft.squaredNorm();
    if (fs2 > cap * cap) {
      ft *= cap / std::sqrt(fs2);
      h.shear = -ft / st;
    } else if (law.damping) {
      out.dashpot_t = tangential_dashpot(law, st, k.m_star);
      ft -= out.dashpot_t * (vd - vdn * n);
    }
    out.force += ft;
    out.elastic_energy += 0.5 * st * h.shear.squaredNorm();
  } else {
    h.shear.setZero();
  }

  if (!law.rolling) {
    h.roll.setZero();
    return;
  }
  const double mu_r = law.roll.coefficient;
  switch (law.roll.model) {
    case RollingModel::kStandard: {
      const double mag = mu_r * std::abs(fn_contact);
      out.roll_i = mag * k.radius_i;
      out.roll_j = mag * k.radius_j;  // 0 against a wall
      break;
    }
    case RollingModel::kStandardCom: {
      const double mag = mu_r * std::abs(fn_contact);
      out.roll_i = mag * k.arm_i;
      out.roll_j = mag * k.arm_j;
      break;
    }
    case RollingModel::kCdt: {
      // As LIGGGHTS 3.8 rolling_model_cdt.h: the elastic (Hertz) normal force k_n δ, the
      // direction of ω_rel = ω_i − ω_j, and the twisting (normal) part of the torque removed.
      const Eigen::Vector3d wr = k.omega_i - k.omega_j;
      const double wn = wr.norm();
      if (wn > 0.0) {
        Eigen::Vector3d tq = (mu_r * k.r_star * f_hertz / wn) * wr;
        tq -= tq.dot(n) * n;
        out.torque_i = -tq;
        out.torque_j = tq;
      }
      break;
    }
    case RollingModel::kEpsd: {
      // Rolling (not twisting) part of the relative rotation.
      Eigen::Vector3d wr = k.omega_i - k.omega_j;
      wr -= wr.dot(n) * n;
      const double kr = 2.25 * sn * mu_r * mu_r * k.r_star * k.r_star;
      h.roll = project_to_tangent(h.roll, n) - kr * dt * wr;
      const double cap = mu_r * k.r_star * std::abs(fn_contact);
      const double mr = h.roll.norm();
      Eigen::Vector3d torque = h.roll;
      if (mr > cap) {
        h.roll *= cap / mr;
        torque = h.roll;  // fully mobilised: no viscous part (type C)
      } else {
        const double inertia = k.m_star * k.r_star * k.r_star;
        torque -= law.roll.viscous_damping * 2.0 * std::sqrt(inertia * kr) * wr;
      }
      out.torque_i = torque;
      out.torque_j = -torque;
      out.elastic_energy += kr > 0.0 ? 0.5 * h.roll.squaredNorm() / kr : 0.0;
      break;
    }
  }
}

}  // namespace clumpkit::dem
