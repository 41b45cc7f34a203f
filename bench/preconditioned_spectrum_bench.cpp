// The spectrum of the preconditioned Hessian P H that L-BFGS works with, at states of a run:
// which modes the multilevel preconditioner (solvers/preconditioner.hpp) leaves slow, where they
// lie, and which additions to P would take them out (docs/performance.md, "Where the
// preconditioner leaves slow modes").
//
// Problem: the Fig. 4.11 pair's full box (the example's run file) at a lower discretization
// order, fields 0, 5, ..., 35 mT upwards, relaxed with the default minimiser (seed profile; at
// n_d = 3 the pair snaps into contact at 25 mT; 79,054 nodes, where the default uses the
// multilevel preconditioner). At the states after 20 mT and after the last field the bench
// takes the Hessian of the conservative neighbour potential at fixed M (what the correction
// passes minimise: MessSystem::hessian_product with CentreRule::all_nodes) in the minimiser's
// scaled variables (u in l_e, the potential in F0 l_e), builds the multilevel preconditioner
// there with each node scaling, and runs preconditioned conjugate gradients on H u = b (b random,
// fixed seed). It prints:
//
// - the CG iterations to each decade of ||r|| / ||b||;
// - the Lanczos matrix's eigenvalues (Ritz values), which approximate the spectrum of P H: the
//   largest, the smallest, and for the 16 smallest their ratio to the largest, the condition
//   number left once the smaller ones are taken out and the CG iterations per decade it implies
//   (sqrt(kappa) ln(10) / 2), where the Ritz vector's weight lies (the particles' nodes, a disc
//   of polymer about the pair's midpoint 2 um in radius and 1 um either side, the rest), the
//   volume terms' share of its stiffness-term energy and that energy over the diagonal's (small
//   for a smooth mode); how many Ritz values lie below 1e-3, 1e-2 and 1e-1 of the largest;
// - CG with P as the minimiser builds it (node blocks and the gap blocks of
//   solvers/contact_gap_blocks.hpp, where the pair is in contact);
// - CG again with one addition to P (node blocks, no gap blocks), each a coarse space solved
// exactly with its
//   Galerkin operator at the state or a block solved exactly: the particles' rigid motions (6
//   per particle); the polymer between the pair (two sizes) with its block of the elastic
//   Hessian; the 8, 32 and 64 smallest Ritz vectors of this state and of the earlier one; with
//   --hats S the trilinear hats of a grid S lattice planes apart (plain, and with each
//   particle moving rigidly with its centre), exact, with their Galerkin diagonal only, and as
//   overlapping patches of 8 points (2 x 2 x 2) each solved exactly.
//
//   ./build/preconditioned_spectrum_bench [--order N] [--steps K] [--lanczos L] [--hats S]
//
// --order: n_d (default 3); --steps: field steps after 0 mT (default 7); --lanczos: CG
// iterations (default 300); --hats: the grid of the hats experiment (default 0: not run; it
// keeps 3 vectors per grid point: S = 4 at n_d = 2 takes about 1.2 GB). Both threads unless
// OMP_NUM_THREADS says otherwise.
#include <fmt/format.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "mresim/config/table_reader.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/solvers/leapfrog.hpp"
#include "mresim/mess/solvers/preconditioner.hpp"
#include "mresim/mess/solvers/stiffness_terms.hpp"
#include "spectrum_tools.hpp"

namespace {

namespace mm = mresim::mess;
namespace mp = mresim::mess_protocol;
using mresim::bench::CgSpectrum;
using mresim::bench::CoarseSpace;

struct Options {
  int order = 3;
  int steps = 7;
  int lanczos = 300;
  int hats = 0;
};

// The system at a relaxed state, in the minimiser's variables.
struct Problem {
  mm::MessSystem system;
  double l_e = 0.0;
  double force_scale = 0.0;
  mm::DofMap map;
  Eigen::Matrix3Xd state;
  Eigen::Matrix3Xd centres;

  explicit Problem(const mm::MessSystem& relaxed)
      : system(with_neighbour_centres(relaxed)),
        l_e(system.length_scale()),
        force_scale(mm::LeapfrogScales::of(system.lattice()).k_eff * l_e),
        map(system.constraints(), system.positions(), l_e),
        state(system.positions()),
        centres(system.particle_centres()) {}

  // H v in the minimiser's variables.
  [[nodiscard]] Eigen::VectorXd hessian(const Eigen::VectorXd& v) const {
    return map.reduce(system.hessian_product(l_e * map.expand(v))) / (force_scale * l_e);
  }
  // A node field (3 x N, units of l_e) as a vector of the free variables.
  [[nodiscard]] Eigen::VectorXd variables(const Eigen::Matrix3Xd& v) const {
    return map.reduce(v) / l_e;
  }

 private:
  static mm::MessSystem with_neighbour_centres(const mm::MessSystem& relaxed) {
    mm::MessSystem s = relaxed;
    s.settings().centre_rule = mm::CentreRule::all_nodes;
    s.apply_constraints();
    return s;
  }
};

// Where a node field's weight lies.
struct Location {
  double particles = 0.0;
  double disc = 0.0;  // polymer within 2 um of the pair's axis and 1 um of its midpoint
  double rest = 0.0;
};

Location locate(const Problem& problem, const Eigen::Matrix3Xd& v) {
  const Eigen::Vector3d mid = 0.5 * (problem.centres.col(0) + problem.centres.col(1));
  const Eigen::Vector3d axis = (problem.centres.col(1) - problem.centres.col(0)).normalized();
  const auto& particle_of_node = problem.system.lattice().particle_of_node;
  Location l;
  for (Eigen::Index n = 0; n < v.cols(); ++n) {
    const double w = v.col(n).squaredNorm();
    const Eigen::Vector3d d = problem.state.col(n) - mid;
    const double along = d.dot(axis);
    if (particle_of_node[static_cast<std::size_t>(n)] >= 0) {
      l.particles += w;
    } else if (std::abs(along) < 1e-6 && (d - along * axis).norm() < 2e-6) {
      l.disc += w;
    } else {
      l.rest += w;
    }
  }
  const double total = l.particles + l.disc + l.rest;
  return {l.particles / total, l.disc / total, l.rest / total};
}

// The stiffness terms' energy of a node field v (stiffness_terms.hpp): the volume terms' share,
// and the energy over the diagonal's (near 1 for a field that alternates from node to node).
struct ModeCharacter {
  double volume_share = 0.0;
  double over_diagonal = 0.0;
};

ModeCharacter characterise(const Problem& problem, const Eigen::Matrix3Xd& v) {
  double springs = 0.0;
  double cells = 0.0;
  double diagonal = 0.0;
  const mm::MessSystem& system = problem.system;
  mm::for_each_stiffness_term(
      system.lattice(), &problem.state, problem.map, system.settings().elastic.volume_force_factor,
      1.0,
      [&](std::int64_t i, std::int64_t j, const Eigen::Vector3d& u, double c) {
        const double d = u.dot(v.col(j) - v.col(i));
        springs += c * d * d;
        diagonal += c * (std::pow(u.dot(v.col(i)), 2) + std::pow(u.dot(v.col(j)), 2));
      },
      [&](const auto& element, const mresim::lattice::CellVertices& g, double c) {
        double d = 0.0;
        for (std::size_t k = 0; k < 8; ++k) {
          const double part = g[k].dot(v.col(element[k]));
          d += part;
          diagonal += c * part * part;
        }
        cells += c * d * d;
      });
  return {cells / (springs + cells), (springs + cells) / diagonal};
}

void print_spectrum_table(const Problem& problem, const CgSpectrum& s) {
  const Eigen::Index k = s.ritz.size();
  const double top = s.ritz(k - 1);
  std::printf("  Ritz values: largest %.4g, smallest %.4g, ratio %.4g\n", top, s.ritz(0),
              top / s.ritz(0));
  std::printf("  %4s %12s %13s %13s %9s %9s %9s %9s %9s\n", "j", "ritz/largest", "kappa after j",
              "CG its/decade", "particles", "disc", "rest", "volume", "A/diag");
  for (Eigen::Index j = 0; j < std::min<Eigen::Index>(16, k - 1); ++j) {
    const Eigen::Matrix3Xd y = problem.map.expand(s.ritz_vector(j));
    const Location where = locate(problem, y);
    const ModeCharacter character = characterise(problem, y);
    const double kappa = top / s.ritz(j);
    std::printf("  %4lld %12.4e %13.4g %13.1f %9.3f %9.3f %9.3f %9.3f %9.4f\n",
                static_cast<long long>(j), s.ritz(j) / top, kappa,
                std::sqrt(kappa) * std::log(10.0) / 2.0, where.particles, where.disc, where.rest,
                character.volume_share, character.over_diagonal);
  }
  for (const double fraction : {1e-3, 1e-2, 1e-1}) {
    const auto below = std::count_if(s.ritz.data(), s.ritz.data() + k,
                                     [&](double r) { return r < fraction * top; });
    std::printf("  Ritz values below %.0e of the largest: %lld\n", fraction,
                static_cast<long long>(below));
  }
}

// The particles' rigid motions (3 translations, 3 rotations about the centre, per particle).
Eigen::MatrixXd rigid_motions(const Problem& problem) {
  const auto& particles = problem.system.lattice().particle_nodes;
  Eigen::MatrixXd w(problem.map.size(), 6 * static_cast<Eigen::Index>(particles.size()));
  for (std::size_t q = 0; q < particles.size(); ++q) {
    const auto p = static_cast<Eigen::Index>(q);
    for (int mode = 0; mode < 6; ++mode) {
      Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Zero(3, problem.system.node_count());
      for (const std::int32_t n : particles[q]) {
        const Eigen::Vector3d arm = (problem.state.col(n) - problem.centres.col(p)) / problem.l_e;
        v.col(n) = mode < 3 ? Eigen::Vector3d(Eigen::Vector3d::Unit(mode))
                            : Eigen::Vector3d(Eigen::Vector3d::Unit(mode - 3).cross(arm));
      }
      w.col(6 * p + mode) = problem.variables(v);
    }
  }
  return w;
}

// The polymer nodes within `radius` of the pair's axis and `half` of its midpoint, solved exactly
// with their block of the elastic Hessian (springs and cells at the state, exact: the compressed
// springs' negative part included; its non-positive eigenvalues dropped).
class GapBlock {
 public:
  GapBlock(const Problem& problem, double radius, double half) {
    const Eigen::Vector3d mid = 0.5 * (problem.centres.col(0) + problem.centres.col(1));
    const Eigen::Vector3d axis = (problem.centres.col(1) - problem.centres.col(0)).normalized();
    const auto& lattice = problem.system.lattice();
    std::vector<Eigen::Index> coordinates;
    for (Eigen::Index n = 0; n < lattice.node_count(); ++n) {
      if (lattice.particle_of_node[static_cast<std::size_t>(n)] >= 0) continue;
      const Eigen::Vector3d d = problem.state.col(n) - mid;
      const double along = d.dot(axis);
      if (std::abs(along) >= half || (d - along * axis).norm() >= radius) continue;
      for (int a = 0; a < 3; ++a) {
        const Eigen::Index dof = problem.map.dof_of(n, a);
        if (dof < 0) continue;
        dofs_.push_back(dof);
        coordinates.push_back(3 * n + a);
      }
    }
    const Eigen::SparseMatrix<double> h = problem.system.elastic_hessian();
    const auto m = static_cast<Eigen::Index>(dofs_.size());
    std::vector<Eigen::Index> local_of(static_cast<std::size_t>(h.rows()), -1);
    for (Eigen::Index k = 0; k < m; ++k) {
      local_of[static_cast<std::size_t>(coordinates[static_cast<std::size_t>(k)])] = k;
    }
    Eigen::MatrixXd local = Eigen::MatrixXd::Zero(m, m);
    for (Eigen::Index k = 0; k < m; ++k) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(h,
                                                         coordinates[static_cast<std::size_t>(k)]);
           it; ++it) {
        const Eigen::Index r = local_of[static_cast<std::size_t>(it.row())];
        if (r >= 0) local(r, k) = it.value() * problem.l_e / problem.force_scale;
      }
    }
    inverse_ = mresim::bench::positive_inverse(local, 1e-12, &dropped_);
  }
  [[nodiscard]] Eigen::VectorXd apply(const Eigen::VectorXd& v) const {
    const auto m = static_cast<Eigen::Index>(dofs_.size());
    Eigen::VectorXd x(m);
    for (Eigen::Index k = 0; k < m; ++k) x(k) = v(dofs_[static_cast<std::size_t>(k)]);
    const Eigen::VectorXd y = inverse_ * x;
    Eigen::VectorXd out = Eigen::VectorXd::Zero(v.size());
    for (Eigen::Index k = 0; k < m; ++k) out(dofs_[static_cast<std::size_t>(k)]) = y(k);
    return out;
  }
  [[nodiscard]] std::size_t size() const { return dofs_.size(); }
  [[nodiscard]] Eigen::Index dropped() const { return dropped_; }

 private:
  std::vector<Eigen::Index> dofs_;
  Eigen::MatrixXd inverse_;
  Eigen::Index dropped_ = 0;
};

// The trilinear hats of a grid `stride` lattice planes apart (3 per point, points numbered
// iz + pz (ix + px iy) as the lattice numbers its nodes); with `rigid`, every particle node takes
// the mean of its centre voxel's corners' values (the particle moves with the field at its
// centre). `points` gets {px, py, pz}.
Eigen::MatrixXd hats(const Problem& problem, int stride, bool rigid, std::array<int, 3>& points) {
  const auto& lattice = problem.system.lattice();
  const auto& shape = lattice.shape;
  const auto wx = mresim::bench::hat_weights(shape.nx(), stride);
  const auto wy = mresim::bench::hat_weights(shape.ny(), stride);
  const auto wz = mresim::bench::hat_weights(shape.nz(), stride);
  points = {static_cast<int>(wx.size()), static_cast<int>(wy.size()), static_cast<int>(wz.size())};
  Eigen::MatrixXd w(problem.map.size(),
                    3 * static_cast<Eigen::Index>(wx.size() * wy.size() * wz.size()));
  Eigen::Index column = 0;
  for (const auto& hy : wy) {
    for (const auto& hx : wx) {
      for (const auto& hz : wz) {
        Eigen::VectorXd value(problem.system.node_count());
        for (int iy = 0; iy < shape.ny(); ++iy) {
          for (int ix = 0; ix < shape.nx(); ++ix) {
            for (int iz = 0; iz < shape.nz(); ++iz) {
              value(shape.node_index(ix, iy, iz)) = hy[static_cast<std::size_t>(iy)] *
                                                    hx[static_cast<std::size_t>(ix)] *
                                                    hz[static_cast<std::size_t>(iz)];
            }
          }
        }
        if (rigid) {
          for (const auto& nodes : lattice.particle_nodes) {
            double centre = 0.0;
            for (std::size_t k = 0; k < 8; ++k) centre += value(nodes[k]) / 8.0;
            for (const std::int32_t n : nodes) value(n) = centre;
          }
        }
        for (int a = 0; a < 3; ++a) {
          Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Zero(3, problem.system.node_count());
          v.row(a) = value.transpose();
          w.col(column++) = problem.variables(v);
        }
      }
    }
  }
  return w;
}

// Overlapping patches of a hat grid: for every grid cell its 8 points' 24 columns, solved exactly
// with their block of the Galerkin operator.
class HatPatches {
 public:
  HatPatches(const CoarseSpace& space, const std::array<int, 3>& points) : w_(space.w()) {
    const auto column = [&](int jx, int jy, int jz) {
      return 3 * static_cast<Eigen::Index>(jz + points[2] * (jx + points[0] * jy));
    };
    for (int jy = 0; jy + 1 < points[1]; ++jy) {
      for (int jx = 0; jx + 1 < points[0]; ++jx) {
        for (int jz = 0; jz + 1 < points[2]; ++jz) {
          std::vector<Eigen::Index> columns;
          for (int c = 0; c < 8; ++c) {
            const Eigen::Index first =
                column(jx + (c & 1), jy + ((c >> 1) & 1), jz + ((c >> 2) & 1));
            for (int a = 0; a < 3; ++a) columns.push_back(first + a);
          }
          Eigen::MatrixXd local(24, 24);
          for (int r = 0; r < 24; ++r) {
            for (int q = 0; q < 24; ++q) {
              local(r, q) = space.galerkin()(columns[static_cast<std::size_t>(r)],
                                             columns[static_cast<std::size_t>(q)]);
            }
          }
          inverses_.push_back(mresim::bench::positive_inverse(local, 1e-12));
          columns_.push_back(std::move(columns));
        }
      }
    }
  }
  [[nodiscard]] Eigen::VectorXd apply(const Eigen::VectorXd& v) const {
    const Eigen::VectorXd wv = w_.transpose() * v;
    Eigen::VectorXd coarse = Eigen::VectorXd::Zero(wv.size());
    for (std::size_t k = 0; k < columns_.size(); ++k) {
      Eigen::VectorXd local(24);
      for (std::size_t r = 0; r < 24; ++r) local(static_cast<Eigen::Index>(r)) = wv(columns_[k][r]);
      const Eigen::VectorXd out = inverses_[k] * local;
      for (std::size_t r = 0; r < 24; ++r) {
        coarse(columns_[k][r]) += out(static_cast<Eigen::Index>(r));
      }
    }
    return w_ * coarse;
  }

 private:
  const Eigen::MatrixXd& w_;
  std::vector<std::vector<Eigen::Index>> columns_;
  std::vector<Eigen::MatrixXd> inverses_;
};

// Analyses one relaxed state; returns the 64 smallest Ritz vectors of P H (node blocks), for the
// next state's test of vectors kept from an earlier state.
Eigen::MatrixXd analyse(const mm::MessSystem& relaxed, const std::string& label,
                        const Options& options, const Eigen::MatrixXd& earlier) {
  const Problem problem(relaxed);
  const auto hessian = [&](const Eigen::VectorXd& v) { return problem.hessian(v); };
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> normal;
  Eigen::VectorXd b(problem.map.size());
  for (Eigen::Index k = 0; k < b.size(); ++k) b(k) = normal(rng);
  std::printf("\n%s: %lld free variables, separation %.5f um\n", label.c_str(),
              static_cast<long long>(problem.map.size()),
              1e6 * (problem.centres.col(1) - problem.centres.col(0)).norm());
  std::printf("  CG iterations to each decade of ||r|| / ||b||:\n");

  Eigen::MatrixXd smallest;
  for (const auto scaling : {mm::NodeScaling::diagonal, mm::NodeScaling::blocks}) {
    const mm::RigidParticlePreconditioner p(problem.system, problem.map, problem.force_scale, true,
                                            &problem.state, nullptr, scaling, mm::ContactGap::none);
    const auto apply = [&](const Eigen::VectorXd& v) { return p.apply(problem.map, v); };
    const CgSpectrum s = mresim::bench::cg_spectrum(hessian, apply, b, options.lanczos, true);
    const bool blocks = scaling == mm::NodeScaling::blocks;
    mresim::bench::print_cg_line(blocks ? "P, node blocks" : "P, diagonal", s);
    print_spectrum_table(problem, s);
    if (!blocks) continue;

    // Each addition to P, one at a time.
    const auto try_addition = [&](const std::string& name, const auto& addition) {
      const auto corrected = [&](const Eigen::VectorXd& v) {
        return Eigen::VectorXd(apply(v) + addition(v));
      };
      mresim::bench::print_cg_line(
          "+ " + name, mresim::bench::cg_spectrum(hessian, corrected, b, options.lanczos, false));
    };
    const auto coarse = [&](const CoarseSpace& c) {
      return [&c](const Eigen::VectorXd& v) { return c.apply(v); };
    };
    {
      const mm::RigidParticlePreconditioner with_gaps(problem.system, problem.map,
                                                      problem.force_scale, true, &problem.state);
      const mm::ContactGapBlocks* gaps = with_gaps.contact_gaps();
      mresim::bench::print_cg_line(
          fmt::format("P as the minimiser builds it (node blocks, {} gap blocks, {} dofs)",
                      gaps != nullptr ? gaps->gaps() : 0, gaps != nullptr ? gaps->dofs() : 0),
          mresim::bench::cg_spectrum(
              hessian, [&](const Eigen::VectorXd& v) { return with_gaps.apply(problem.map, v); }, b,
              options.lanczos, false));
    }
    const CoarseSpace rigid(rigid_motions(problem), hessian);
    try_addition("the particles' rigid motions", coarse(rigid));
    for (const auto& [radius, half] : {std::pair{1.5e-6, 1e-6}, std::pair{2.5e-6, 1.5e-6}}) {
      const GapBlock gap(problem, radius, half);
      try_addition(fmt::format("the polymer between the pair, {} dofs ({:.1f} um, {:.1f} um; "
                               "{} dropped)",
                               gap.size(), 1e6 * radius, 1e6 * half, gap.dropped()),
                   [&gap](const Eigen::VectorXd& v) { return gap.apply(v); });
    }
    const Eigen::Index kept = std::min<Eigen::Index>(64, s.ritz.size());
    smallest.resize(b.size(), kept);
    for (Eigen::Index j = 0; j < kept; ++j) smallest.col(j) = s.ritz_vector(j);
    for (const Eigen::Index count : {8, 32, 64}) {
      if (count <= kept) {
        const CoarseSpace own(smallest.leftCols(count), hessian);
        try_addition(fmt::format("its {} smallest Ritz vectors", count), coarse(own));
      }
      if (count <= earlier.cols() && earlier.rows() == b.size()) {
        const CoarseSpace old(earlier.leftCols(count), hessian);
        try_addition(fmt::format("the earlier state's {} smallest Ritz vectors", count),
                     coarse(old));
      }
    }
    if (options.hats <= 0) continue;
    for (const bool rigid_particles : {false, true}) {
      std::array<int, 3> points{};
      const CoarseSpace space(hats(problem, options.hats, rigid_particles, points), hessian);
      const std::string name = fmt::format("hats {} planes apart{}", options.hats,
                                           rigid_particles ? ", particles rigid" : "");
      try_addition(name + ", exact", coarse(space));
      const Eigen::VectorXd inverse_diagonal = space.galerkin().diagonal().cwiseInverse();
      try_addition(name + ", Galerkin diagonal", [&](const Eigen::VectorXd& v) {
        return Eigen::VectorXd(space.w() *
                               inverse_diagonal.cwiseProduct(space.w().transpose() * v));
      });
      const HatPatches patches(space, points);
      try_addition(name + ", 2 x 2 x 2 patches",
                   [&patches](const Eigen::VectorXd& v) { return patches.apply(v); });
    }
  }
  return smallest;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  for (int k = 1; k < argc; k += 2) {
    const std::string key = argv[k];
    int* value = key == "--order"     ? &options.order
                 : key == "--steps"   ? &options.steps
                 : key == "--lanczos" ? &options.lanczos
                 : key == "--hats"    ? &options.hats
                                      : nullptr;
    if (value == nullptr || k + 1 >= argc) {
      std::fprintf(stderr, "unknown option %s (--order N, --steps K, --lanczos L, --hats S)\n",
                   argv[k]);
      return 2;
    }
    *value = std::max(value == &options.hats ? 0 : 1, std::atoi(argv[k + 1]));
  }
  double load[3] = {};
  if (getloadavg(load, 3) > 0) std::printf("load average at start: %.2f\n", load[0]);
  const mresim::mess_config::MessSpec spec =
      mresim::mess_config::read_mess_run_file(mresim::config::TableReader::parse_file(
          std::string(MRESIM_SOURCE_DIR) + "/examples/chapter4/fig4_11_pair_large_box_S6_5um.toml",
          {fmt::format("model.discretization_order={}", options.order),
           fmt::format("field.max={}", 0.005 * options.steps),
           fmt::format("field.steps={}", options.steps), "field.sequence=\"up\"",
           "output.node_positions=false", "output.checkpoint_every=0"}));
  mp::ProtocolRunner runner(spec);
  mp::ProtocolState state = runner.initial_state();
  std::printf("Fig. 4.11 pair, full box, n_d = %d: %lld nodes\n", options.order,
              static_cast<long long>(runner.system().node_count()));
  Eigen::MatrixXd earlier;
  while (state.next_step < runner.steps().size()) {
    const mp::StepRecord& record = runner.run_next_step(state);
    const double field = 1e3 * record.step.field.norm();
    std::printf("step %zu (%.0f mT): %lld iterations, converged %s\n", record.step.index, field,
                static_cast<long long>(record.iterations), record.converged ? "yes" : "no");
    if (!record.converged) return 1;
    if (std::abs(field - 20.0) < 1e-6 || state.next_step == runner.steps().size()) {
      earlier = analyse(runner.system(), fmt::format("after {:.0f} mT", field), options, earlier);
    }
  }
  return 0;
}
