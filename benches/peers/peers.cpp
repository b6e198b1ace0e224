// The peer side of `benches/peers.py`: the rows of its table computed with
// Pinocchio, built against the library the `pin` wheel ships
// (libpinocchio_default, explicit template instantiations: the algorithms
// run as the wheel's builders compiled them).
//
//   peers MODEL FRAME STATES check           the rows' values on the states (%.17g)
//   peers MODEL FRAME STATES time MS         ns per call of each row (≥ MS ms of calls each)
//   peers MODEL FRAME STATES count CALLS     CALLS calls of each row inside measured_ROW
//                                            (for valgrind --tool=callgrind)
//
// MODEL: Pinocchio's model of the URDF, parsed by the same wheel's URDF
// parser from Python (`pinocchio.buildModelFromUrdf`) and written with
// `Model.saveToText` (17 significant digits: the doubles round-trip exactly);
// the wheel ships no urdfdom headers to parse it from C++.
//
// STATES: a text file "K n" then K rows of q, q̇, q̈ (3n numbers each). The
// rows (`benches/peers.py` has the same list for the core):
//
//   pose_jacobian  the tool frame's pose and its 6 × n LOCAL_WORLD_ALIGNED Jacobian
//   jdot_qdot      the frame's classical acceleration at q̈ = 0 (J̇ q̇), LOCAL_WORLD_ALIGNED
//   rnea           τ = M q̈ + C q̇ + G
//   crba           M(q) (upper triangle: what crba fills)
//   impedance      τ = Jᵀ(−K e − D J q̇) + (I − Jᵀ(J Jᵀ + Λ²)⁻¹ J)(k_n (q_n − q) − d_n q̇),
//                  e = [p − p_d; Log(R R_dᵀ)] (SPEC (16.2), the core's rotation error),
//                  the target (p_d, R_d) the frame's pose at the first state's q, q_n that q
//                  (SPEC (20.7))

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/serialization.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace pin = pinocchio;
using Vec = Eigen::VectorXd;
using Mat6x = pin::Data::Matrix6x;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// q: Pinocchio's configuration (nq: cos θ, sin θ for a continuous joint);
// angle: the joint angles (nv), as the states file and the core have them.
struct State {
  Vec q, angle, dq, ddq;
};

struct Ctx {
  pin::Model model;
  pin::Data data;
  pin::FrameIndex frame;
  std::vector<State> states;
  Mat6x J;
  // The impedance law's parameters (SPEC (20.7)): K, D (N/m, N m/rad; N s/m,
  // N m s/rad), k_n (1/s²), d_n (1/s), Λ² (m², 1), the target and posture.
  Vec6 K, D, lambda2;
  double kn = 25.0, dn = 10.0;
  Eigen::Vector3d pd;
  Eigen::Matrix3d Rd;
  Vec qn;
  Vec tau;
  double sink = 0.0;
};

static std::vector<State> read_states(const char *path, const pin::Model &model) {
  const int nv = model.nv;
  std::ifstream f(path);
  int k = 0, n = 0;
  f >> k >> n;
  if (!f || n != nv) {
    std::fprintf(stderr, "%s: expected a header 'K %d'\n", path, nv);
    std::exit(2);
  }
  std::vector<State> out(k);
  for (auto &s : out) {
    s.angle.resize(n);
    s.dq.resize(n);
    s.ddq.resize(n);
    for (int i = 0; i < n; ++i) f >> s.angle[i];
    for (int i = 0; i < n; ++i) f >> s.dq[i];
    for (int i = 0; i < n; ++i) f >> s.ddq[i];
  }
  if (!f) {
    std::fprintf(stderr, "%s: fewer numbers than K rows of 3n\n", path);
    std::exit(2);
  }
  // The configuration a Pinocchio user passes: the angle itself, or its cosine
  // and sine for a joint without limits (JointModelRUB*, nq = 2).
  for (auto &s : out) {
    s.q.resize(model.nq);
    for (pin::JointIndex j = 1; j < (pin::JointIndex)model.njoints; ++j) {
      const int iq = model.idx_qs[j], iv = model.idx_vs[j];
      if (model.nqs[j] == 2) {
        s.q[iq] = std::cos(s.angle[iv]);
        s.q[iq + 1] = std::sin(s.angle[iv]);
      } else {
        s.q[iq] = s.angle[iv];
      }
    }
  }
  return out;
}

// Log(R) as a rotation vector through the unit quaternion on w ≥ 0 (SPEC (16.2)).
static Eigen::Vector3d log_rotation(const Eigen::Matrix3d &r) {
  Eigen::Quaterniond q(r);
  double w = q.w();
  Eigen::Vector3d v = q.vec();
  if (w < 0.0) {
    w = -w;
    v = -v;
  }
  const double s = v.norm();
  if (s < 1e-9) return (2.0 / w) * v;  // θ/sin(θ/2) = 2/cos(θ/2) (1 + O(θ²))
  return (2.0 * std::atan2(s, w) / s) * v;
}

// --- the rows -------------------------------------------------------------

static inline void pose_jacobian(Ctx &c, const State &s) {
  pin::computeFrameJacobian(c.model, c.data, s.q, c.frame, pin::LOCAL_WORLD_ALIGNED, c.J);
}

static inline Vec6 jdot_qdot(Ctx &c, const State &s) {
  pin::forwardKinematics(c.model, c.data, s.q, s.dq, Vec::Zero(c.model.nv));
  return pin::getFrameClassicalAcceleration(c.model, c.data, c.frame, pin::LOCAL_WORLD_ALIGNED)
      .toVector();
}

static inline const Vec &rnea(Ctx &c, const State &s) {
  return pin::rnea(c.model, c.data, s.q, s.dq, s.ddq);
}

static inline const Eigen::MatrixXd &crba(Ctx &c, const State &s) {
  return pin::crba(c.model, c.data, s.q, pin::Convention::LOCAL);
}

static inline const Vec &impedance(Ctx &c, const State &s) {
  pin::computeFrameJacobian(c.model, c.data, s.q, c.frame, pin::LOCAL_WORLD_ALIGNED, c.J);
  const pin::SE3 &x = c.data.oMf[c.frame];
  Vec6 e;
  e.head<3>() = x.translation() - c.pd;
  e.tail<3>() = log_rotation(x.rotation() * c.Rd.transpose());
  const Vec6 f = -c.K.cwiseProduct(e) - c.D.cwiseProduct(c.J * s.dq);
  const Vec t0 = c.kn * (c.qn - s.angle) - c.dn * s.dq;
  Mat6 a = c.J * c.J.transpose();
  a.diagonal() += c.lambda2;
  const Vec6 y = a.llt().solve(c.J * t0);
  c.tau.noalias() = c.J.transpose() * (f - y);
  c.tau += t0;
  return c.tau;
}

// One noinline function per row, for callgrind's --toggle-collect=measured_*.
extern "C" {
__attribute__((noinline)) void measured_pose_jacobian(Ctx &c, long calls) {
  const size_t k = c.states.size();
  for (long i = 0; i < calls; ++i) {
    pose_jacobian(c, c.states[i % k]);
    c.sink += c.J(0, 0) + c.data.oMf[c.frame].translation()[0];
  }
}
__attribute__((noinline)) void measured_jdot_qdot(Ctx &c, long calls) {
  const size_t k = c.states.size();
  for (long i = 0; i < calls; ++i) c.sink += jdot_qdot(c, c.states[i % k])[0];
}
__attribute__((noinline)) void measured_rnea(Ctx &c, long calls) {
  const size_t k = c.states.size();
  for (long i = 0; i < calls; ++i) c.sink += rnea(c, c.states[i % k])[0];
}
__attribute__((noinline)) void measured_crba(Ctx &c, long calls) {
  const size_t k = c.states.size();
  for (long i = 0; i < calls; ++i) c.sink += crba(c, c.states[i % k])(0, 0);
}
__attribute__((noinline)) void measured_impedance(Ctx &c, long calls) {
  const size_t k = c.states.size();
  for (long i = 0; i < calls; ++i) c.sink += impedance(c, c.states[i % k])[0];
}
}

typedef void (*Row)(Ctx &, long);
static const struct {
  const char *name;
  Row run;
} ROWS[] = {
    {"pose_jacobian", measured_pose_jacobian},
    {"jdot_qdot", measured_jdot_qdot},
    {"rnea", measured_rnea},
    {"crba", measured_crba},
    {"impedance", measured_impedance},
};

static void print(const char *what, const double *v, long n) {
  std::printf("%s", what);
  for (long i = 0; i < n; ++i) std::printf(" %.17g", v[i]);
  std::printf("\n");
}

int main(int argc, char **argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s MODEL FRAME STATES check|time MS|count CALLS\n", argv[0]);
    return 2;
  }
  Ctx c;
  c.model.loadFromText(argv[1]);
  c.data = pin::Data(c.model);
  if (!c.model.existFrame(argv[2])) {
    std::fprintf(stderr, "the model has no frame %s\n", argv[2]);
    return 2;
  }
  // The link's own frame where a joint or another frame has its name too.
  c.frame = c.model.existFrame(argv[2], pin::BODY) ? c.model.getFrameId(argv[2], pin::BODY)
                                                   : c.model.getFrameId(argv[2]);
  for (pin::JointIndex j = 1; j < (pin::JointIndex)c.model.njoints; ++j) {
    if (c.model.nvs[j] != 1) {
      std::fprintf(stderr, "joint %s has %d degrees of freedom: not a serial arm\n",
                   c.model.names[j].c_str(), c.model.nvs[j]);
      return 2;
    }
  }
  const int n = c.model.nv;
  c.states = read_states(argv[3], c.model);
  c.J = Mat6x::Zero(6, n);
  c.K << 500, 500, 500, 20, 20, 20;
  for (int i = 0; i < 6; ++i) c.D[i] = 2.0 * std::sqrt(c.K[i]);
  c.lambda2.setConstant(1e-4);
  c.qn = c.states[0].angle;
  pin::framesForwardKinematics(c.model, c.data, c.states[0].q);
  c.pd = c.data.oMf[c.frame].translation();
  c.Rd = c.data.oMf[c.frame].rotation();
  c.tau = Vec::Zero(n);
  const std::string mode = argv[4];

  if (mode == "check") {
    for (const State &s : c.states) {
      pose_jacobian(c, s);
      const pin::SE3 &x = c.data.oMf[c.frame];
      Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r = x.rotation();
      print("position", x.translation().data(), 3);
      print("rotation", r.data(), 9);
      Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor> j = c.J;
      print("jacobian", j.data(), 6 * n);
      const Vec6 a = jdot_qdot(c, s);
      print("jdot_qdot", a.data(), 6);
      print("rnea", rnea(c, s).data(), n);
      Eigen::MatrixXd m = crba(c, s);
      m.triangularView<Eigen::StrictlyLower>() = m.transpose();
      print("crba", m.data(), n * n);
      print("impedance", impedance(c, s).data(), n);
    }
    return 0;
  }
  if (mode == "time") {
    const double ms = argc > 5 ? std::atof(argv[5]) : 50.0;
    for (const auto &row : ROWS) {
      row.run(c, 2000);  // warm
      long calls = 1000;
      double ns = 0.0;
      for (;;) {
        const auto t0 = std::chrono::steady_clock::now();
        row.run(c, calls);
        const auto t1 = std::chrono::steady_clock::now();
        const double spent = std::chrono::duration<double, std::nano>(t1 - t0).count();
        if (spent >= ms * 1e6) {
          ns = spent / calls;
          break;
        }
        calls *= 2;
      }
      std::printf("%s %.3f\n", row.name, ns);
    }
    std::fprintf(stderr, "sink %g\n", c.sink);
    return 0;
  }
  if (mode == "count") {
    const long calls = argc > 5 ? std::atol(argv[5]) : 1000;
    for (const auto &row : ROWS) row.run(c, calls);
    std::fprintf(stderr, "sink %g\n", c.sink);
    return 0;
  }
  std::fprintf(stderr, "unknown mode %s\n", mode.c_str());
  return 2;
}
