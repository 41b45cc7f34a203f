// How the cost of one 3D relaxation grows with the lattice: the same physical system (two
// particles, R = 1.5 um, 6.5454 um apart along z in an 8 x 8 x 14.7 um box, particle volume
// fraction 3 %, all faces held) discretised at n_d = 1 ... 5 (1.3k to 41k nodes), relaxed after the
// field steps from 0 to 40 mT along z, with each method's default convergence criteria
// (max force 1e-6 k_eff l_e). Prints per size and method: nodes, wall and CPU time, outer
// iterations (Newton or L-BFGS steps), inner iterations (CG), evaluations, and the agreement
// of the final states; then the exponent p of time ~ N^p fitted over n_d = 2 ... 5 and the
// time ratios measured in this run. Methods: newton, lbfgs (rigid-particle preconditioner:
// run files' method = "lbfgs"), minimiser (the same L-BFGS with the multilevel preconditioner,
// LbfgsPreconditioner::multilevel: the run files' default above kMultilevelMinimumNodes, with
// its pairs in single precision; minimiser-d the same with them in double precision),
// lbfgs-mg (L-BFGS with Newton's multigrid as its initial inverse Hessian,
// LbfgsPreconditioner::multigrid) and, for the seed profile, lbfgs-exact (its correction passes
// each resolved to the force tolerance: MinimiserOptions::correction_forcing = 0, against the
// default's inexact passes). For the seed profile it then relaxes the field loop 0, 5, ..., 40 mT
// (in this box the pair stays apart) with lbfgs and lbfgs-exact at n_d <= 3
// (--loop-max-order) and prints their evaluations and ratio. docs/performance.md records the
// results.
//
//   ./build/mess_scaling_bench                      (seed profile, n_d = 1..5, all three methods)
//   ./build/mess_scaling_bench --orders 1,2,3 --profile physical --lbfgs-max-order 3
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "mresim/core/constants.hpp"
#include "mresim/mess/lattice/lattice.hpp"
#include "mresim/mess/profile/model_profile.hpp"
#include "mresim/mess/protocols/loading.hpp"
#include "mresim/mess/solvers/minimiser.hpp"

namespace {

namespace mess = mresim::mess;
namespace lat = mresim::lattice;

constexpr double kRadius = 1.5e-6;
constexpr double kSeparation = 6.5454e-6;
// 8 x 8 x 14.7 um: 2 x 4/3 pi R^3 / V = 3 %; long in z so that n_d = 1 still fits the pair.
constexpr double kSide = 8e-6;
constexpr double kHeight = 14.7e-6;
constexpr double kField = 0.04;  // T

mess::MessSystem make_system(const mess::ModelProfile& profile, int order) {
  lat::LatticeSpec spec;
  profile.apply_to(spec);
  spec.discretization_order = order;
  const double l_e = lat::element_length(kRadius, order);
  // Odd cell counts, so that the centre cell is the box's middle; centre cells nearest to the
  // physical positions, mirror-symmetric in z.
  const auto odd_cells = [&](double length) {
    return 2 * static_cast<int>(std::lround(0.5 * (length / l_e - 1.0))) + 1;
  };
  const int side = odd_cells(kSide);
  const int height = odd_cells(kHeight);
  const int half_gap = static_cast<int>(std::lround(0.5 * kSeparation / l_e));
  const int centre_cell = side / 2;
  const double middle = (centre_cell + 0.5) * l_e;  // the centre cell's centre
  lat::ByHandPlacement placement;
  placement.box.lengths = Eigen::Vector3d(side, side, height) * l_e;
  for (const int k : {height / 2 - half_gap, height / 2 + half_gap}) {
    placement.positions.emplace_back(middle, middle, (k + 0.5) * l_e);
  }
  spec.placement = placement;
  mess::MessSystem sys = mess::MessSystem::make(
      lat::build_lattice(spec), Eigen::Vector3d(0.0, 0.0, kField) / mresim::kMu0, profile);
  // The hysteresis runs' boundary condition: all six faces held.
  sys.set_constraints(
      mresim::mess_protocol::hysteresis_load(sys.lattice(), sys.lattice().positions).constraints);
  return sys;
}

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct Outcome {
  mess::MinimiserResult result;
  double wall = 0.0;
  double cpu = 0.0;
  Eigen::Matrix3Xd centres;  // l_e
  Eigen::Matrix3Xd magnetizations;
};

Outcome relax(const mess::ModelProfile& profile, int order, mess::MinimiserMethod method,
              mess::LbfgsPreconditioner preconditioner = mess::LbfgsPreconditioner::rigid_particles,
              double correction_forcing = mess::MinimiserOptions{}.correction_forcing,
              mess::LbfgsHistoryPrecision history = mess::LbfgsHistoryPrecision::automatic) {
  mess::MessSystem sys = make_system(profile, order);
  mess::MinimiserOptions options;
  options.method = method;
  options.lbfgs_preconditioner = preconditioner;
  options.correction_forcing = correction_forcing;
  options.lbfgs_history = history;
  Outcome o;
  const auto start = std::chrono::steady_clock::now();
  const double cpu0 = cpu_seconds();
  o.result = mess::minimise(sys, options);
  o.cpu = cpu_seconds() - cpu0;
  o.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.centres = sys.particle_centres() / sys.length_scale();
  o.magnetizations = sys.magnetizations() / sys.model().particles.Ms;
  return o;
}

void print(int order, std::int64_t nodes, const char* method, const Outcome& o) {
  const mess::MinimiserResult& r = o.result;
  std::printf(
      "n_d=%d %8lld nodes  %-11s  wall %8.2f s  cpu %8.2f s  outer %6d  inner %7lld  "
      "evaluations %7lld  setup %6.2f s  %s%s\n",
      order, static_cast<long long>(nodes), method, o.wall, o.cpu, r.iterations,
      static_cast<long long>(r.krylov_iterations), static_cast<long long>(r.evaluations),
      r.preconditioner_seconds, mess::to_string(r.status).c_str(),
      r.finished_with_lbfgs ? " (finished with lbfgs)" : "");
  if (r.multigrid_seconds > 0.0) {
    std::printf(
        "        %s parts: multigrid %.2f s, Hessian products %.2f s, centre Hessians "
        "%.2f s, setup %.2f s\n",
        method, r.multigrid_seconds, r.hessian_product_seconds, r.centre_hessian_seconds,
        r.preconditioner_seconds);
  }
  std::fflush(stdout);
}

// The time ratio to a reference method measured in this run, and how far apart the final
// states are.
void print_against(const char* method, const Outcome& o, const char* reference_name,
                   const Outcome& reference) {
  std::printf(
      "        %s/%s wall %.2fx, cpu %.2fx; max |centre difference| %.2e l_e, "
      "max |M/Ms difference| %.2e\n",
      method, reference_name, o.wall / reference.wall, o.cpu / reference.cpu,
      (o.centres - reference.centres).cwiseAbs().maxCoeff(),
      (o.magnetizations - reference.magnetizations).cwiseAbs().maxCoeff());
}

// The field loop 0, 5, ..., 40 mT along z, each step relaxed from the one before.
Outcome relax_loop(const mess::ModelProfile& profile, int order, double correction_forcing) {
  mess::MessSystem sys = make_system(profile, order);
  mess::MinimiserOptions options;
  options.lbfgs_preconditioner = mess::LbfgsPreconditioner::rigid_particles;  // "lbfgs"
  options.correction_forcing = correction_forcing;
  Outcome o;
  const auto start = std::chrono::steady_clock::now();
  const double cpu0 = cpu_seconds();
  for (int step = 0; step <= 8; ++step) {
    sys.set_applied_field(Eigen::Vector3d(0.0, 0.0, 0.005 * step) / mresim::kMu0);
    const mess::MinimiserResult r = mess::minimise(sys, options);
    o.result.evaluations += r.evaluations;
    o.result.iterations += r.iterations;
    o.result.converged = step == 0 ? r.converged : o.result.converged && r.converged;
  }
  o.cpu = cpu_seconds() - cpu0;
  o.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.centres = sys.particle_centres() / sys.length_scale();
  o.magnetizations = sys.magnetizations() / sys.model().particles.Ms;
  return o;
}

void print_loop(int order, const char* method, const Outcome& o) {
  std::printf(
      "n_d=%d loop 0..40 mT  %-11s  wall %8.2f s  cpu %8.2f s  iterations %7d  "
      "evaluations %7lld  %s\n",
      order, method, o.wall, o.cpu, o.result.iterations,
      static_cast<long long>(o.result.evaluations),
      o.result.converged ? "all converged" : "NOT ALL CONVERGED");
  std::fflush(stdout);
}

struct LbfgsWalls {
  double lbfgs = 0.0;
  double minimiser = 0.0;
};

// The L-BFGS variants at one order, each printed with its ratio to its reference (newton's
// outcome n for lbfgs): lbfgs, minimiser, minimiser-d and, for the seed profile, lbfgs-exact.
LbfgsWalls relax_lbfgs_variants(const mess::ModelProfile& profile, const std::string& profile_name,
                                int order, std::int64_t nodes, const Outcome& n) {
  const Outcome l = relax(profile, order, mess::MinimiserMethod::lbfgs);
  print(order, nodes, "lbfgs", l);
  print_against("lbfgs", l, "newton", n);
  const Outcome ml =
      relax(profile, order, mess::MinimiserMethod::lbfgs, mess::LbfgsPreconditioner::multilevel);
  print(order, nodes, "minimiser", ml);
  print_against("minimiser", ml, "lbfgs", l);
  // The same with the pairs in double precision (the minimiser's own are single).
  const Outcome md = relax(
      profile, order, mess::MinimiserMethod::lbfgs, mess::LbfgsPreconditioner::multilevel,
      mess::MinimiserOptions{}.correction_forcing, mess::LbfgsHistoryPrecision::double_precision);
  print(order, nodes, "minimiser-d", md);
  print_against("minimiser", ml, "minimiser-d", md);
  if (profile_name == "seed") {  // only the seed profile has correction passes
    const Outcome e = relax(profile, order, mess::MinimiserMethod::lbfgs,
                            mess::LbfgsPreconditioner::rigid_particles, 0.0);
    print(order, nodes, "lbfgs-exact", e);
    print_against("lbfgs-exact", e, "lbfgs", l);
  }
  return {l.wall, ml.wall};
}

// Least-squares slope of log t against log N.
double exponent(const std::vector<double>& nodes, const std::vector<double>& seconds) {
  double sx = 0.0;
  double sy = 0.0;
  double sxx = 0.0;
  double sxy = 0.0;
  const auto n = static_cast<double>(nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const double x = std::log(nodes[k]);
    const double y = std::log(seconds[k]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

std::vector<int> parse_orders(const std::string& text) {
  std::vector<int> orders;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) orders.push_back(std::stoi(item));
  return orders;
}

}  // namespace

int main(int argc, char** argv) {
  std::string profile_name = "seed";
  std::vector<int> orders = {1, 2, 3, 4, 5};
  int lbfgs_max_order = 5;
  int multigrid_lbfgs_max_order = 5;
  int loop_max_order = 3;
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string key = argv[k];
    if (key == "--profile") {
      profile_name = argv[k + 1];
    } else if (key == "--orders") {
      orders = parse_orders(argv[k + 1]);
    } else if (key == "--lbfgs-max-order") {
      lbfgs_max_order = std::stoi(argv[k + 1]);
    } else if (key == "--lbfgs-mg-max-order") {
      multigrid_lbfgs_max_order = std::stoi(argv[k + 1]);
    } else if (key == "--loop-max-order") {
      loop_max_order = std::stoi(argv[k + 1]);
    } else {
      std::fprintf(stderr,
                   "unknown option %s (--profile, --orders, --lbfgs-max-order, "
                   "--lbfgs-mg-max-order, --loop-max-order)\n",
                   argv[k]);
      return 2;
    }
  }
  const mess::ModelProfile& profile = mess::model_profile(profile_name);
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) > 0) std::printf("load average at start: %.2f\n", load[0]);
  std::printf("profile %s, 0 -> %.0f mT, OpenMP threads as set by OMP_NUM_THREADS\n",
              profile_name.c_str(), 1e3 * kField);
  std::vector<double> nodes_fit;
  std::vector<double> newton_fit;
  std::vector<double> lbfgs_fit;
  std::vector<double> minimiser_fit;
  std::vector<double> multigrid_lbfgs_fit;
  for (const int order : orders) {
    const std::int64_t nodes = make_system(profile, order).node_count();
    const Outcome n = relax(profile, order, mess::MinimiserMethod::newton);
    print(order, nodes, "newton", n);
    if (order <= lbfgs_max_order) {
      const LbfgsWalls walls = relax_lbfgs_variants(profile, profile_name, order, nodes, n);
      if (order >= 2) {
        lbfgs_fit.push_back(walls.lbfgs);
        minimiser_fit.push_back(walls.minimiser);
      }
    }
    if (order <= multigrid_lbfgs_max_order) {
      const Outcome m =
          relax(profile, order, mess::MinimiserMethod::lbfgs, mess::LbfgsPreconditioner::multigrid);
      print(order, nodes, "lbfgs-mg", m);
      print_against("lbfgs-mg", m, "newton", n);
      if (order >= 2) multigrid_lbfgs_fit.push_back(m.wall);
    }
    if (order >= 2) {
      nodes_fit.push_back(static_cast<double>(nodes));
      newton_fit.push_back(n.wall);
    }
  }
  if (nodes_fit.size() >= 2) {
    std::printf("time ~ N^p over n_d >= 2: newton p = %.2f", exponent(nodes_fit, newton_fit));
    if (lbfgs_fit.size() == nodes_fit.size()) {
      std::printf(", lbfgs p = %.2f", exponent(nodes_fit, lbfgs_fit));
    }
    if (minimiser_fit.size() == nodes_fit.size()) {
      std::printf(", minimiser p = %.2f", exponent(nodes_fit, minimiser_fit));
    }
    if (multigrid_lbfgs_fit.size() == nodes_fit.size()) {
      std::printf(", lbfgs-mg p = %.2f", exponent(nodes_fit, multigrid_lbfgs_fit));
    }
    std::printf("\n");
  }
  if (profile_name == "seed") {  // only the seed profile has correction passes
    for (const int order : orders) {
      if (order > loop_max_order) continue;
      const Outcome l = relax_loop(profile, order, mess::MinimiserOptions{}.correction_forcing);
      print_loop(order, "lbfgs", l);
      const Outcome e = relax_loop(profile, order, 0.0);
      print_loop(order, "lbfgs-exact", e);
      std::printf(
          "        loop: lbfgs-exact/lbfgs evaluations %.2fx\n",
          static_cast<double>(e.result.evaluations) / static_cast<double>(l.result.evaluations));
      print_against("lbfgs-exact", e, "lbfgs", l);
    }
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::printf("peak resident memory of the process: %.1f MiB\n",
              static_cast<double>(usage.ru_maxrss) / 1024.0);
  return 0;
}
