// The solves of the contact gap's factor (solvers/contact_gap_blocks.hpp): what the minimisers'
// preconditioner pays once per L-BFGS iteration while a pair is in contact. They are split over
// the factor's elimination tree so that two threads share them (solvers/split_cholesky_solve.hpp);
// this bench measures that against the plain serial forward and back substitution through the
// same factor, in the same run.
//
// Problem: the Fig. 4.11 pair (284,592 nodes) from its run file with the particles 3.3 um apart
// (2.2 radii, as in contact), all six faces held; the gap's block at the rest lattice (the same
// nodes and pattern as at a contact state). Printed: the gap's size, the split (entries of L in
// each branch and in the trunk), the best time of one application of the gap's inverse with 1
// and 2 threads and of the serial substitution, their ratios, whether 2 threads give bitwise the
// result of 1, the largest difference from the serial substitution (rounding: the trunk's terms
// are summed in another order), and the load average.
//
//   ./build/contact_gap_bench [--repeats 50]
#include <omp.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "full_size_systems.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"
#include "mresim/mess/solvers/contact_gap_blocks.hpp"

namespace {

namespace mess = mresim::mess;
using mresim::bench::best_seconds;

std::string pair_in_contact_run_file() {
  const std::string path =
      std::string(MRESIM_SOURCE_DIR) + "/examples/chapter4/fig4_11_pair_large_box_S6_5um.toml";
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::string toml = text.str();
  const std::string key = "separation = 6.5454e-6";
  const auto at = toml.find(key);
  if (at == std::string::npos) {
    std::fprintf(stderr, "%s: no '%s' to change\n", path.c_str(), key.c_str());
    std::exit(1);
  }
  toml.replace(at, key.size(), "separation = 3.3e-6");
  return toml;
}

}  // namespace

int main(int argc, char** argv) {
  const auto options = mresim::bench::parse_bench_options(argc, argv, 50);
  if (!options) return 2;
  mresim::bench::print_load_average();
  const auto spec = mresim::mess_config::read_mess_run_file(
      mresim::config::TableReader::parse_string(pair_in_contact_run_file(), "fig4_11 in contact"));
  const mresim::mess_protocol::ProtocolRunner runner(spec);
  mess::MessSystem system = runner.system();
  mresim::bench::hold_all_faces(system);
  system.apply_constraints();
  const mess::DofMap map(system.constraints(), system.positions(), system.length_scale());
  const mess::ContactGapBlocks gaps(system, map, 1e-9, system.positions());
  if (gaps.gaps() != 1) {
    std::fprintf(stderr, "expected one gap, found %zu\n", gaps.gaps());
    return 1;
  }
  const auto& lower = gaps.factor(0).matrixL().nestedExpression();
  const auto& split = gaps.solves(0);
  std::printf("Fig. 4.11 pair 3.3 um apart: %lld nodes; the gap %lld coordinates, L %lld entries\n",
              static_cast<long long>(system.node_count()), static_cast<long long>(gaps.dofs()),
              static_cast<long long>(lower.nonZeros()));
  std::printf(
      "split: branches %ld and %ld entries, trunk %ld (%.1f %%)\n", split.branch_entries()[0],
      split.branch_entries()[1], split.trunk_entries(),
      100.0 * static_cast<double>(split.trunk_entries()) / static_cast<double>(lower.nonZeros()));

  std::mt19937_64 random(20261207);
  std::normal_distribution<double> normal;
  Eigen::VectorXd b(lower.cols());
  for (Eigen::Index k = 0; k < b.size(); ++k) b[k] = normal(random);
  Eigen::VectorXd serial = b;
  Eigen::VectorXd y;
  const double t_serial = best_seconds(options->repeats, [&] {
    serial = b;
    mess::detail::serial_cholesky_solve(lower, serial);
  });
  Eigen::VectorXd one;
  double t_one = 0.0;
  for (const int threads : {1, 2}) {
    omp_set_num_threads(threads);
    const double t = best_seconds(options->repeats, [&] {
      y = b;
      split.solve(lower, y);
    });
    const double difference = (y - serial).cwiseAbs().maxCoeff() / serial.cwiseAbs().maxCoeff();
    std::printf(
        "  %d thread%s: split solves %7.3f ms (serial substitution %7.3f ms: %.2fx); "
        "largest difference from it %.2e relative\n",
        threads, threads == 1 ? " " : "s", 1e3 * t, 1e3 * t_serial, t_serial / t, difference);
    if (threads == 1) {
      one = y;
      t_one = t;
    } else {
      std::printf("  2 threads against 1: %.2fx; the result %s\n", t_one / t,
                  one == y ? "bitwise the same" : "DIFFERS");
    }
  }
  return 0;
}
