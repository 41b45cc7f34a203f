// mess_hysteresis (Section 4.2.7, Figs. 4.4-4.9): the field loop 0 -> max -> -max -> max with all
// six faces of the box held at the initial lattice, one relaxation per field. No table of its
// own, no load, no analysis beyond the per-step outputs (magnetization, separations, clusters).

#include <memory>

#include "mresim/mess/protocols/loading.hpp"
#include "mresim/mess/protocols/protocol.hpp"

namespace mresim::mess_protocol {
namespace {

class Hysteresis final : public Protocol {
 public:
  [[nodiscard]] LoadState load(const lattice::Lattice& lattice, const StepSpec& /*step*/,
                               const Eigen::Matrix3Xd& reference) const override {
    return hysteresis_load(lattice, reference);
  }
};

const ProtocolRegistrar hysteresis_protocol_registrar(
    {"mess_hysteresis",
     "3D lattice (MESS): field loop with all faces held (Chapter 4)",
     {},
     [](const config::TableReader& /*root*/) { return std::make_shared<const Hysteresis>(); },
     mess_config::FieldSequence::loop,
     1});

}  // namespace
}  // namespace mresim::mess_protocol
