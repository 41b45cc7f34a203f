// Tests of the self-consistent magnetization of N particles (Section 4.2.3, eqs. 4.55-4.58):
// symmetric solutions, the zero-field instability of touching particles with chi = 70, a
// low-symmetry near-contact triple on which the dissertation's fixed point fails and the
// fallback chain succeeds, residual checks, the demagnetized susceptibility limit, and
// independence from the start and from the thread count.

#include "mresim/mess/magnetization/self_consistent.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

#include "../../support/dissertation_values.hpp"
#include "../support/dissertation_particles.hpp"
#include "../support/mess_test_support.hpp"
#include "mresim/core/constants.hpp"
#include "mresim/magnetism/froehlich_kennelly.hpp"

namespace mm = mresim::magnetism;
using mm::MagnetizationMethod;

namespace {

// The dissertation's particles: R = 1.5 um, chi0 = 70, Ms = 1.6e6 A/m.
using mresim::mess::testing::centres_in_radii;  // columns in units of R
using mresim::mess::testing::kParticles;
using mresim::testing::kMs;
using mresim::testing::kR;

using mresim::mess::testing::tesla;  // H_ext = B_ext / mu0

// A low-symmetry near-contact triple (gaps 0.22 R and 0.12 R, no two bonds aligned, oblique
// field of 72 mT) found by a search over random triangles: the plain fixed point oscillates
// for ever, Anderson acceleration converges to a saddle of the energy, Newton to a minimum.
const Eigen::Matrix3Xd kTriple =
    centres_in_radii({{0.0, 0.0, 0.0}, {-1.39, 0.04, -1.73}, {-2.79, -0.10, -0.15}});
const Eigen::Vector3d kTripleField = tesla(-0.036, -0.043, -0.045);

// Another near-contact triple (23 mT) where the fixed point crawls and Anderson finishes.
const Eigen::Matrix3Xd kCrawlTriple =
    centres_in_radii({{0.0, 0.0, 0.0}, {1.70, -0.54, 1.36}, {0.40, 0.87, 2.51}});
const Eigen::Vector3d kCrawlField = tesla(0.015, 0.016, 0.005);

// Well separated particles (>= 3.2 R apart): one solution, fixed point contracts.
using mresim::mess::testing::kLoose;

const Eigen::Matrix3Xd kNoHistory;  // 0 columns: start from FK(H_ext)

mm::MagnetizationOptions only(std::vector<MagnetizationMethod> methods) {
  mm::MagnetizationOptions o;
  o.methods = std::move(methods);
  return o;
}

mm::MagnetizationOptions tight(mm::MagnetizationOptions o = {}) {
  o.atol = 1e-12;
  o.rtol = 0.0;
  return o;
}

// Residual recomputed independently of the solver: eq. 4.55 (froehlich_kennelly.hpp) of
// H_ext + sum_j eq. 4.57, in units of Ms.
Eigen::Matrix3Xd independent_residual(const Eigen::Matrix3Xd& c, const Eigen::Matrix3Xd& M,
                                      const Eigen::Vector3d& H_ext) {
  const double V = kParticles.volume();
  Eigen::Matrix3Xd r(3, c.cols());
  for (int i = 0; i < c.cols(); ++i) {
    Eigen::Vector3d H = H_ext;
    for (int j = 0; j < c.cols(); ++j) {
      if (j == i) continue;
      const Eigen::Vector3d d = c.col(i) - c.col(j);
      const double s = d.norm();
      const Eigen::Vector3d n = d / s;
      H += V / (4.0 * std::numbers::pi) * (3.0 * n * M.col(j).dot(n) - M.col(j)) / (s * s * s);
    }
    r.col(i) = (mresim::magnetism::froehlich_kennelly(H, kParticles.chi0, kMs) - M.col(i)) / kMs;
  }
  return r;
}

bool meets_tolerance(const Eigen::Matrix3Xd& r, const Eigen::Matrix3Xd& M, double atol,
                     double rtol) {
  for (Eigen::Index k = 0; k < r.size(); ++k) {
    if (std::abs(r.data()[k]) > atol + rtol * std::abs(M.data()[k] / kMs)) return false;
  }
  return true;
}

// m = M/Ms of a symmetric pair at centre distance r (units of R) along a field h = H/Ms:
// the scalar equation m = FK(h + a m), a = (2/3)(R/r)^3, solved by bisection.
double symmetric_pair_m(double r_over_R, double h) {
  const double a = 2.0 / 3.0 / std::pow(r_over_R, 3);
  const double chi = kParticles.chi0;
  double lo = 0.0;
  double hi = 1.0;
  for (int k = 0; k < 200; ++k) {
    const double m = 0.5 * (lo + hi);
    const double hl = h + a * m;
    (chi * hl / (1.0 + chi * hl) > m ? lo : hi) = m;
  }
  return lo;
}

}  // namespace

TEST(ParticleMagnetization, TwoParticlesAlongTheFieldAreSymmetric) {
  const Eigen::Matrix3Xd c = centres_in_radii({{0.0, 0.0, 0.0}, {0.0, 0.0, 2.2}});
  const Eigen::Vector3d H = tesla(0.0, 0.0, 0.05);
  const mm::MagnetizationResult res =
      mm::solve_magnetization(c, kParticles, H, kNoHistory, tight());
  ASSERT_TRUE(res.converged);
  EXPECT_EQ(res.method, MagnetizationMethod::fixed_point);
  EXPECT_NEAR((res.M.col(0) - res.M.col(1)).norm(), 0.0, 1e-12 * kMs);  // M1 = M2
  EXPECT_EQ(res.M(0, 0), 0.0);  // nothing transverse to the field
  EXPECT_EQ(res.M(1, 0), 0.0);
  // The scalar equation of the symmetric pair.
  const double h = H.z() / kMs;
  const double chi = kParticles.chi0;
  const double lo = symmetric_pair_m(2.2, h);
  EXPECT_NEAR(res.M(2, 0) / kMs, lo, 1e-11);
  // Mutual magnetization along the bond enhances M over the isolated particle's.
  EXPECT_GT(lo, 1.2 * chi * h / (1.0 + chi * h));
}

// chi0 (2/3)(R/r)^3 > 1 for r < 5.40 um: M = 0 is then an unstable solution at zero field and
// a seeded pair keeps the remanent m = 1 - 1/(chi0 a) (docs/original-code.md#magnetization quotes
// 0.762, 0.596, 0.213 at 3.35, 4.0, 5.0 um from the original solver, to its tolerance).
TEST(ParticleMagnetization, TouchingPairHasZeroFieldRemanenceFromHistory) {
  const double chi = kParticles.chi0;
  struct Case {
    double r_um;
    double seed_tolerance_value;
  };
  for (const Case& k : {Case{3.35, 0.762}, Case{4.0, 0.596}, Case{5.0, 0.213}}) {
    const double r = k.r_um * 1e-6;
    const Eigen::Matrix3Xd c = centres_in_radii({{0.0, 0.0, 0.0}, {0.0, 0.0, r / kR}});
    Eigen::Matrix3Xd history(3, 2);
    history.col(0) = history.col(1) = Eigen::Vector3d(0.0, 0.0, 0.9 * kMs);
    mm::MagnetizationOptions o = tight();
    o.check_stability = true;
    const mm::MagnetizationResult seeded =
        mm::solve_magnetization(c, kParticles, Eigen::Vector3d::Zero(), history, o);
    const double a = 2.0 / 3.0 * std::pow(kR / r, 3);
    ASSERT_TRUE(seeded.converged) << k.r_um;
    EXPECT_NEAR(seeded.M(2, 0) / kMs, 1.0 - 1.0 / (chi * a), 1e-9) << k.r_um;
    EXPECT_NEAR(seeded.M(2, 0) / kMs, k.seed_tolerance_value, 0.01) << k.r_um;
    EXPECT_EQ(seeded.stability, mm::Stability::stable);
    EXPECT_GT(seeded.min_hessian_eigenvalue, 0.0);

    // Without history (FK of the zero field = 0) the solver returns the exact but unstable
    // solution M = 0, and the stability check says so.
    const mm::MagnetizationResult fresh =
        mm::solve_magnetization(c, kParticles, Eigen::Vector3d::Zero(), kNoHistory, o);
    ASSERT_TRUE(fresh.converged);
    EXPECT_EQ(fresh.M.norm(), 0.0);
    EXPECT_EQ(fresh.stability, mm::Stability::unstable);
  }
  // Beyond r = R (2 chi/3)^(1/3) = 5.40 um the remanence is gone.
  const Eigen::Matrix3Xd far = centres_in_radii({{0.0, 0.0, 0.0}, {0.0, 0.0, 6.545e-6 / kR}});
  Eigen::Matrix3Xd history(3, 2);
  history.col(0) = history.col(1) = Eigen::Vector3d(0.0, 0.0, 0.9 * kMs);
  mm::MagnetizationOptions o = tight();
  o.max_fixed_point_iterations = 1000;
  o.check_stability = true;
  const mm::MagnetizationResult res =
      mm::solve_magnetization(far, kParticles, Eigen::Vector3d::Zero(), history, o);
  ASSERT_TRUE(res.converged);
  EXPECT_LT(res.M.norm() / kMs, 1e-10);
  EXPECT_EQ(res.stability, mm::Stability::stable);
}

// The dissertation's failure mode, reproduced: the plain fixed point does not converge on a
// low-symmetry near-contact triple, however long it runs; it is not slow, it oscillates.
TEST(ParticleMagnetization, FixedPointFailsOnNearContactTriple) {
  mm::MagnetizationOptions o = only({MagnetizationMethod::fixed_point});
  o.max_fixed_point_iterations = 2000;
  o.stall_window = 0;  // no early exit
  const mm::MagnetizationResult res =
      mm::solve_magnetization(kTriple, kParticles, kTripleField, kNoHistory, o);
  EXPECT_FALSE(res.converged);
  EXPECT_GT(res.scaled_residual, 10.0);
  ASSERT_EQ(res.attempts.size(), 1u);
  EXPECT_EQ(res.attempts[0].iterations, 2000);
  EXPECT_FALSE(res.attempts[0].converged);
  // The state it returns is still labelled with its true residual.
  EXPECT_NEAR(res.residual,
              independent_residual(kTriple, res.M, kTripleField).cwiseAbs().maxCoeff(), 1e-12);

  // Default options: the stall detector hands over after a few dozen iterations.
  const mm::MagnetizationResult stalled = mm::solve_magnetization(
      kTriple, kParticles, kTripleField, kNoHistory, only({MagnetizationMethod::fixed_point}));
  EXPECT_FALSE(stalled.converged);
  EXPECT_LT(stalled.attempts[0].iterations, 60);
}

TEST(ParticleMagnetization, FallbackChainConvergesOnNearContactTripleAndSaysHow) {
  mm::MagnetizationOptions o;
  o.check_stability = true;
  const mm::MagnetizationResult res =
      mm::solve_magnetization(kTriple, kParticles, kTripleField, kNoHistory, o);
  ASSERT_TRUE(res.converged);
  EXPECT_EQ(res.method, MagnetizationMethod::newton);
  ASSERT_EQ(res.attempts.size(), 3u);
  EXPECT_EQ(res.attempts[0].method, MagnetizationMethod::fixed_point);
  EXPECT_FALSE(res.attempts[0].converged);
  EXPECT_EQ(res.attempts[1].method, MagnetizationMethod::anderson);
  EXPECT_FALSE(res.attempts[1].converged);
  EXPECT_TRUE(res.attempts[1].rejected_unstable);  // it found a saddle, not a minimum
  EXPECT_EQ(res.attempts[2].method, MagnetizationMethod::newton);
  EXPECT_TRUE(res.attempts[2].converged);
  EXPECT_EQ(res.iterations, res.attempts[2].iterations);
  EXPECT_EQ(res.total_iterations,
            res.attempts[0].iterations + res.attempts[1].iterations + res.attempts[2].iterations);
  EXPECT_LE(res.scaled_residual, 1.0);
  EXPECT_EQ(res.stability, mm::Stability::stable);
  EXPECT_TRUE(
      meets_tolerance(independent_residual(kTriple, res.M, kTripleField), res.M, 1e-12, 1e-12));

  // Newton converges quadratically: from the original's loose band to 1e-12 takes a handful
  // of iterations.
  mm::MagnetizationOptions loose = mm::MagnetizationOptions::original();
  loose.check_stability = true;
  const mm::MagnetizationResult rough =
      mm::solve_magnetization(kTriple, kParticles, kTripleField, kNoHistory, loose);
  ASSERT_TRUE(rough.converged);
  EXPECT_EQ(rough.method, MagnetizationMethod::newton);
  EXPECT_TRUE(
      meets_tolerance(independent_residual(kTriple, rough.M, kTripleField), rough.M, 1e-3, 5e-3));
  const mm::MagnetizationResult sharp = mm::solve_magnetization(
      kTriple, kParticles, kTripleField, rough.M, only({MagnetizationMethod::newton}));
  ASSERT_TRUE(sharp.converged);
  EXPECT_LE(sharp.iterations, 8);
  EXPECT_LT(independent_residual(kTriple, sharp.M, kTripleField).cwiseAbs().maxCoeff(), 1e-11);
  EXPECT_LT((sharp.M - rough.M).cwiseAbs().maxCoeff() / kMs, 1e-2);  // same state
  EXPECT_LT((sharp.M - res.M).cwiseAbs().maxCoeff() / kMs, 1e-10);
}

TEST(ParticleMagnetization, AndersonIsAcceptedWhereItFindsAMinimum) {
  const mm::MagnetizationResult res =
      mm::solve_magnetization(kCrawlTriple, kParticles, kCrawlField, kNoHistory);
  ASSERT_TRUE(res.converged);
  EXPECT_EQ(res.method, MagnetizationMethod::anderson);
  ASSERT_EQ(res.attempts.size(), 2u);
  EXPECT_FALSE(res.attempts[0].converged);
  EXPECT_FALSE(res.attempts[1].rejected_unstable);
  EXPECT_TRUE(
      meets_tolerance(independent_residual(kCrawlTriple, res.M, kCrawlField), res.M, 1e-12, 1e-12));
}

// Without Newton in the chain a failure is reported, never hidden.
TEST(ParticleMagnetization, ExhaustedChainReportsFailure) {
  mm::MagnetizationOptions o =
      only({MagnetizationMethod::fixed_point, MagnetizationMethod::anderson});
  const mm::MagnetizationResult res =
      mm::solve_magnetization(kTriple, kParticles, kTripleField, kNoHistory, o);
  EXPECT_FALSE(res.converged);
  EXPECT_GT(res.scaled_residual, 1.0);
  EXPECT_EQ(res.attempts.size(), 2u);
  EXPECT_NEAR(res.residual,
              independent_residual(kTriple, res.M, kTripleField).cwiseAbs().maxCoeff(), 1e-12);
}

// Every method on its own, on loose and near-contact configurations: the returned M meets the
// tolerance by an independent evaluation of eqs. 4.55-4.58, and `residual` is its residual.
TEST(ParticleMagnetization, ReturnedResidualIsTheTrueResidual) {
  struct Case {
    const Eigen::Matrix3Xd* centres;
    Eigen::Vector3d field;
  };
  const Case cases[] = {{&kLoose, tesla(0.02, -0.05, 0.1)},
                        {&kLoose, tesla(0.0, 0.3, 0.9)},
                        {&kTriple, kTripleField},
                        {&kCrawlTriple, kCrawlField}};
  for (const Case& k : cases) {
    for (const MagnetizationMethod m :
         {MagnetizationMethod::fixed_point, MagnetizationMethod::anderson,
          MagnetizationMethod::newton}) {
      const mm::MagnetizationResult res =
          mm::solve_magnetization(*k.centres, kParticles, k.field, kNoHistory, only({m}));
      const Eigen::Matrix3Xd r = independent_residual(*k.centres, res.M, k.field);
      EXPECT_NEAR(res.residual, r.cwiseAbs().maxCoeff(), 1e-12) << mm::to_string(m);
      EXPECT_EQ(res.converged, meets_tolerance(r, res.M, 1e-12, 1e-12)) << mm::to_string(m);
      if (k.centres == &kLoose) {
        EXPECT_TRUE(res.converged) << mm::to_string(m);
      }
    }
    // The chain always succeeds here.
    EXPECT_TRUE(mm::solve_magnetization(*k.centres, kParticles, k.field, kNoHistory).converged);
  }
}

// Demagnetization: a lone sphere has the apparent susceptibility chi/(1 + chi/3) in weak
// fields (2.88 for chi = 70) and still saturates; each method agrees.
TEST(ParticleMagnetization, DemagnetizedSingleParticleSusceptibility) {
  const Eigen::Matrix3Xd one = Eigen::Matrix3Xd::Zero(3, 1);
  const double chi = kParticles.chi0;
  for (const MagnetizationMethod m : {MagnetizationMethod::fixed_point,
                                      MagnetizationMethod::anderson, MagnetizationMethod::newton}) {
    mm::MagnetizationOptions o = tight(only({m}));
    o.demagnetization = true;
    const Eigen::Vector3d weak(0.0, 10.0, 0.0);  // A/m
    const mm::MagnetizationResult res =
        mm::solve_magnetization(one, kParticles, weak, kNoHistory, o);
    ASSERT_TRUE(res.converged) << mm::to_string(m);
    EXPECT_NEAR(res.M(1, 0) / weak.y(), chi / (1.0 + chi / 3.0), 1e-3) << mm::to_string(m);
    const Eigen::Vector3d strong(0.0, 0.0, 5.0 / mresim::kMu0);  // 5 T
    const mm::MagnetizationResult sat =
        mm::solve_magnetization(one, kParticles, strong, kNoHistory, o);
    ASSERT_TRUE(sat.converged) << mm::to_string(m);
    // M = FK(H - M/3) exactly.
    const Eigen::Vector3d internal = strong - sat.M.col(0) / 3.0;
    EXPECT_NEAR(sat.M(2, 0), mm::froehlich_kennelly(internal, chi, kMs).z(), 1e-9 * kMs);
    EXPECT_GT(sat.M(2, 0) / kMs, 0.9);
  }
  // Without demagnetization the same weak field gives eq. 4.55, slope chi0 / (1 + chi0 h).
  const mm::MagnetizationResult plain = mm::solve_magnetization(
      one, kParticles, Eigen::Vector3d(0.0, 10.0, 0.0), kNoHistory, tight());
  EXPECT_NEAR(plain.M(1, 0) / 10.0, chi / (1.0 + chi * 10.0 / kMs), 1e-9);
}

// The internal-field law takes the apparent susceptibility below the zero-field threshold:
// a touching pair seeded at 0.9 Ms relaxes to M = 0 (compare the remanence test above).
TEST(ParticleMagnetization, DemagnetizationRemovesTheZeroFieldInstability) {
  const Eigen::Matrix3Xd c = centres_in_radii({{0.0, 0.0, 0.0}, {0.0, 0.0, 2.0}});
  Eigen::Matrix3Xd history(3, 2);
  history.col(0) = history.col(1) = Eigen::Vector3d(0.0, 0.0, 0.9 * kMs);
  mm::MagnetizationOptions o = tight();
  o.demagnetization = true;
  o.max_fixed_point_iterations = 1000;
  o.check_stability = true;
  const mm::MagnetizationResult res =
      mm::solve_magnetization(c, kParticles, Eigen::Vector3d::Zero(), history, o);
  ASSERT_TRUE(res.converged);
  EXPECT_LT(res.M.norm() / kMs, 1e-10);
  EXPECT_EQ(res.stability, mm::Stability::stable);
  // The near-contact triple needs no fallback either.
  mm::MagnetizationOptions d;
  d.demagnetization = true;
  const mm::MagnetizationResult triple =
      mm::solve_magnetization(kTriple, kParticles, kTripleField, kNoHistory, d);
  ASSERT_TRUE(triple.converged);
  EXPECT_EQ(triple.method, MagnetizationMethod::fixed_point);
}

// Where the solution is unique, starting from zero and starting from the solution at a
// neighbouring field (history) give the same answer to the tolerance.
TEST(ParticleMagnetization, FromZeroAndFromHistoryAgree) {
  for (const double b : {0.05, 0.3, 1.2}) {
    const Eigen::Vector3d H = tesla(0.2 * b, -0.1 * b, b);
    const mm::MagnetizationResult previous =
        mm::solve_magnetization(kLoose, kParticles, tesla(0.2 * b, -0.1 * b, 0.9 * b), kNoHistory);
    ASSERT_TRUE(previous.converged);
    const mm::MagnetizationResult from_history =
        mm::solve_magnetization(kLoose, kParticles, H, previous.M);
    const mm::MagnetizationResult from_zero =
        mm::solve_magnetization(kLoose, kParticles, H, Eigen::Matrix3Xd::Zero(3, 4));
    ASSERT_TRUE(from_history.converged);
    ASSERT_TRUE(from_zero.converged);
    // Both within the tolerance of the exact solution, hence of each other.
    const mm::MagnetizationResult exact =
        mm::solve_magnetization(kLoose, kParticles, H, from_history.M, tight());
    ASSERT_TRUE(exact.converged);
    const double tol = 1e-10;  // error ~ residual / (1 - contraction), residual <= 2e-12
    EXPECT_LT((from_history.M - exact.M).cwiseAbs().maxCoeff() / kMs, tol) << b;
    EXPECT_LT((from_zero.M - exact.M).cwiseAbs().maxCoeff() / kMs, tol) << b;
    // History is cheaper.
    EXPECT_LE(from_history.iterations, from_zero.iterations) << b;
  }
}

TEST(ParticleMagnetization, IndependentOfThreadCount) {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const mm::MagnetizationResult one =
      mm::solve_magnetization(kTriple, kParticles, kTripleField, kNoHistory);
  omp_set_num_threads(4);
  const mm::MagnetizationResult four =
      mm::solve_magnetization(kTriple, kParticles, kTripleField, kNoHistory);
  omp_set_num_threads(saved);
  EXPECT_EQ(one.M, four.M);  // bitwise
  EXPECT_EQ(one.total_iterations, four.total_iterations);
}

TEST(ParticleMagnetization, RejectsBadInput) {
  const Eigen::Vector3d H = tesla(0.0, 0.0, 0.1);
  EXPECT_THROW((void)mm::solve_magnetization(kLoose, kParticles, H, Eigen::Matrix3Xd::Zero(3, 2)),
               std::invalid_argument);
  mm::MagnetizationOptions o;
  o.methods.clear();
  EXPECT_THROW((void)mm::solve_magnetization(kLoose, kParticles, H, kNoHistory, o),
               std::invalid_argument);
  o = {};
  o.atol = -1.0;
  EXPECT_THROW((void)mm::solve_magnetization(kLoose, kParticles, H, kNoHistory, o),
               std::invalid_argument);
  mm::MagneticParticles bad = kParticles;
  bad.chi0 = 0.0;
  EXPECT_THROW((void)mm::solve_magnetization(kLoose, bad, H, kNoHistory), std::invalid_argument);
  EXPECT_THROW(
      (void)mm::solve_magnetization(kLoose, kParticles, Eigen::Vector3d(0.0, 0.0, NAN), kNoHistory),
      std::invalid_argument);
  EXPECT_EQ(mm::to_string(MagnetizationMethod::anderson), "anderson");
}

// The default tolerance is the tight one: every solve, fallback chain included, ends with the
// fixed-point residual within 1e-12 + 1e-12 |m| (units of Ms) by an independent evaluation of
// eqs. 4.55-4.58, touching and near-contact configurations included.
TEST(ParticleMagnetization, DefaultToleranceIsTight) {
  const mm::MagnetizationOptions o;
  EXPECT_EQ(o.atol, 1e-12);
  EXPECT_EQ(o.rtol, 1e-12);
  const Eigen::Matrix3Xd touching = centres_in_radii({{0.0, 0.0, 0.0}, {0.3, 0.2, 1.96}});
  struct Case {
    const Eigen::Matrix3Xd* centres;
    Eigen::Vector3d field;
  };
  const Case cases[] = {{&kLoose, tesla(0.02, -0.05, 0.1)},
                        {&kTriple, kTripleField},
                        {&kCrawlTriple, kCrawlField},
                        {&touching, tesla(0.01, 0.0, 0.03)},
                        {&touching, tesla(0.0, 0.0, 1.5)}};
  for (const Case& k : cases) {
    const mm::MagnetizationResult res =
        mm::solve_magnetization(*k.centres, kParticles, k.field, kNoHistory);
    ASSERT_TRUE(res.converged);
    EXPECT_LE(res.scaled_residual, 1.0);
    EXPECT_LE(res.residual, 2e-12);
    EXPECT_TRUE(
        meets_tolerance(independent_residual(*k.centres, res.M, k.field), res.M, 1e-12, 1e-12));
  }
}

// The original code's loose band stays available, by name, everything else at its default.
TEST(ParticleMagnetization, OriginalToleranceIsTheOriginalsLooseBand) {
  mm::MagnetizationOptions o = mm::MagnetizationOptions::original();
  EXPECT_EQ(o.atol, 1e-3);
  EXPECT_EQ(o.rtol, 5e-3);
  const mm::MagnetizationOptions defaults;
  EXPECT_EQ(o.methods, defaults.methods);
  EXPECT_EQ(o.max_fixed_point_iterations, defaults.max_fixed_point_iterations);
  EXPECT_EQ(o.max_newton_iterations, defaults.max_newton_iterations);
  o.set_tolerance(mm::MagnetizationTolerance::tight);
  EXPECT_EQ(o.atol, defaults.atol);
  EXPECT_EQ(o.rtol, defaults.rtol);
  o.set_tolerance(mm::MagnetizationTolerance::original);
  EXPECT_EQ(o.atol, 1e-3);
  EXPECT_EQ(o.rtol, 5e-3);
  EXPECT_EQ(mm::to_string(mm::MagnetizationTolerance::tight), "tight");
  EXPECT_EQ(mm::to_string(mm::MagnetizationTolerance::original), "original");
}

// What the option changes: a pair along a 50 mT field, warm-started from its solution at a
// slightly larger separation (as every re-solve in a relaxation is). The original's band
// accepts a stale M; the tight default gives the exact solution of the scalar pair equation.
TEST(ParticleMagnetization, OriginalToleranceLeavesMStaleTightDoesNot) {
  const Eigen::Vector3d H = tesla(0.0, 0.0, 0.05);
  const Eigen::Matrix3Xd before = centres_in_radii({{0.0, 0.0, 0.0}, {0.0, 0.0, 2.25}});
  const Eigen::Matrix3Xd after = centres_in_radii({{0.0, 0.0, 0.0}, {0.0, 0.0, 2.2}});
  const mm::MagnetizationResult history =
      mm::solve_magnetization(before, kParticles, H, kNoHistory);
  ASSERT_TRUE(history.converged);
  const mm::MagnetizationResult loose = mm::solve_magnetization(
      after, kParticles, H, history.M, mm::MagnetizationOptions::original());
  const mm::MagnetizationResult tight = mm::solve_magnetization(after, kParticles, H, history.M);
  ASSERT_TRUE(loose.converged);
  ASSERT_TRUE(tight.converged);
  const double exact = symmetric_pair_m(2.2, H.z() / kMs);
  // Loose and tight differ by far more than the tight tolerance: the loose M is stale.
  EXPECT_GT(std::abs(loose.M(2, 0) / kMs - tight.M(2, 0) / kMs), 1e-4);  // measured 7e-4
  EXPECT_GT(std::abs(loose.M(2, 0) / kMs - exact), 1e-4);
  // The tight one is self-consistent to ~1e-10 relative, by the residual and by the answer.
  const Eigen::Matrix3Xd r = independent_residual(after, tight.M, H);
  EXPECT_LT(r.cwiseAbs().maxCoeff() / (tight.M.cwiseAbs().maxCoeff() / kMs), 1e-10);
  EXPECT_NEAR(tight.M(2, 0) / kMs, exact, 1e-10 * exact);
  EXPECT_NEAR(tight.M(2, 1) / kMs, exact, 1e-10 * exact);
}
