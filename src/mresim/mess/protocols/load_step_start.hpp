#pragma once

// Where a step of a 3D run starts: a loaded step of a strain run (run file:
// solver.load_step_start) and a field step (solver.field_step_start); docs/run-files-3d.md,
// measured in docs/performance.md ("Strain steps from a predicted start", "Field steps from a
// predicted start").
//
// A strain run relaxes load value k at field f from the relaxed state at load value k - 1 and the
// same field (protocol_runner.hpp), with the moved faces put at load value k. Started from that
// state as it is ("previous", the original code's start), the polymer next to the moved faces
// begins strained by the whole increment, and the minimiser's first hundreds of iterations carry
// it into the box. "extrapolated" starts from a prediction of the new state instead, in the
// strain coordinate c in which the moved faces move linearly (Protocol::measured_strain: tan
// gamma for shear, the engineering strain, the twist angle):
//
//  - k >= 2: the secant through the field's result two load values back (the zero-strain state
//    x_0 at k = 2; ProtocolState::earlier_load_results keeps it),
//        x = x_{k-1} + (c_k - c_{k-1}) / (c_{k-1} - c_{k-2}) (x_{k-1} - x_{k-2}),
//    exact where the response is linear in c between them (secant_start). Through x_0 at every
//    k (the form before) it carried a contact formed at an earlier strain on: on the Fig. 4.25
//    helix at 10 and 20 mT it put two particles 170 nm into each other, and such steps took
//    2.7-3.1x the iterations (docs/performance.md, "The helix's 10 and 20 mT strain steps").
//    The steps go through the fields at each load value, so the previous field's step at the
//    same k has just missed its own secant by m_{f-1} = x_k(f - 1) - S_k(f - 1). The secant's
//    miss comes mostly from the polymer's response to the strain, which changes slowly with
//    the field, so at fields f >= 1 the step is also offered the corrected secants
//        S_k(f) + m_{f-1}   and, from f >= 2,   S_k(f) + m_{f-1} + r (m_{f-1} - m_{f-2})
//    (the miss extrapolated in the field as field_secant_start extrapolates states, r as
//    there), and starts from the lowest of these and the plain secant (take_lowest). On the
//    full-size Fig. 4.25 helix at gamma = 0.11 the corrected secants lay 8-21x (one miss) and
//    27-167x (two) closer in rms than the plain one from 20 and 30 mT on (docs/performance.md,
//    "Strain steps from secants corrected by the previous fields' misses");
//  - k = 1 at a field f >= 1: the zero-strain state plus the previous field's response at the
//    same strain, x = x_0(f) + d_{f-1}, d_g = x_1(g) - x_0(g) (neighbour_field_start); from
//    f >= 2 also offered x_0(f) + d_{f-1} + r (d_{f-1} - d_{f-2}), the response extrapolated in
//    the field (r as in field_secant_start), and started from the lower of the two;
//  - k = 1 at the first field: the previous state (nothing to extrapolate from).
//
// A field step (every step of a field loop or series, the zero-load steps of strain and stress
// runs) starts from the previous field's result x_{f-1}. From the third field on,
// "extrapolated" starts it from the secant through the two previous fields' results instead,
// in the applied field B (a vector; the change projected on the previous change):
//        x = x_{f-1} + r (x_{f-1} - x_{f-2}),
//        r = (B_f - B_{f-1}).(B_{f-1} - B_{f-2}) / |B_{f-1} - B_{f-2}|^2
// (field_secant_start). Along a loop's leg this carries the polymer's response to the last
// field change on to the next; where the loop turns (r = -1) it returns to the state of the
// field before, x_{f-2}.
//
// The prediction is only where the relaxation starts; it ends at the same tolerance. The runner
// keeps it only where its potential is not above that of the previous state with the new faces
// and field: after a jump (particles joining a cluster) the secant would carry the jump on and
// push particles into each other, and such a step starts as before.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "mresim/mess/system/system_energy.hpp"

namespace mresim::mess_protocol {

// How a step's relaxation started (StepRecord::start, /steps/solver/start in results.h5).
namespace step_start {
inline const std::string kInitialLattice = "initial_lattice";  // the run's first step
inline const std::string kPrevious = "previous";  // the state the protocol prescribes, as it is
inline const std::string kSecant = "secant";
inline const std::string kCorrectedSecant = "corrected_secant";
inline const std::string kNeighbourField = "neighbour_field";
inline const std::string kNeighbourFieldSecant = "neighbour_field_secant";
inline const std::string kFieldSecant = "field_secant";
// A prediction was made and rejected (its potential was higher): started as "previous".
inline const std::string kPredictionRejected = "previous_prediction_rejected";
}  // namespace step_start

// x_{k-1} + (c - c_previous) / (c_previous - c_zero) (x_{k-1} - x_0), x_0 (`zero_load`, at
// strain c_zero) the secant's earlier point: the zero-strain state, or the result two load
// values back. Throws std::invalid_argument if the arrays differ in size, a coordinate is not
// finite or c_previous == c_zero.
Eigen::Matrix3Xd secant_start(const Eigen::Matrix3Xd& previous, const Eigen::Matrix3Xd& zero_load,
                              double c, double c_previous, double c_zero);

// x_0(f) + (x_1(f - 1) - x_0(f - 1)). Throws std::invalid_argument if the arrays differ in size.
Eigen::Matrix3Xd neighbour_field_start(const Eigen::Matrix3Xd& zero_load,
                                       const Eigen::Matrix3Xd& neighbour_loaded,
                                       const Eigen::Matrix3Xd& neighbour_zero_load);

// x_{f-1} + r (x_{f-1} - x_{f-2}) with r as above, from the results `previous` (at field
// `b_previous`) and `earlier` (at `b_earlier`). Throws std::invalid_argument if the arrays
// differ in size, a field is not finite or b_previous == b_earlier.
Eigen::Matrix3Xd field_secant_start(const Eigen::Matrix3Xd& previous,
                                    const Eigen::Matrix3Xd& earlier, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& b_previous,
                                    const Eigen::Vector3d& b_earlier);

// Moves `candidate` into the system where its potential is not above that of the system's own
// positions, both at the system's field and constraints (the candidate's held coordinates are
// written from them) with M solved at each from the system's magnetization history. Returns
// whether it did; if not, the system's positions and magnetizations are as they were, bit for
// bit. Makes two evaluations. `candidate` is left with the positions not kept.
bool take_if_not_higher(mess::MessSystem& system, Eigen::Matrix3Xd& candidate);

// Of `candidates`, moves into the system the one with the lowest potential where that is not
// above the potential of the system's own positions (on a tie the earlier candidate), each
// evaluated as take_if_not_higher does. Returns its index, or -1 where none was taken (the
// system's positions and magnetizations as they were, bit for bit). Makes 1 + size()
// evaluations. The candidates not taken are left in `candidates`, the system's own positions
// in the entry of the one taken.
int take_lowest(mess::MessSystem& system, std::vector<Eigen::Matrix3Xd>& candidates);

}  // namespace mresim::mess_protocol
