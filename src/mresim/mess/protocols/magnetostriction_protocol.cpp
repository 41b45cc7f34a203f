// mess_magnetostriction (Section 4.2.7): a field series with only the bottom face (z = 0) held,
// so the free body lengthens or shortens along the field. No table of its own, no load; the
// deformation is read from the per-step outputs (system volume, node positions).

#include <memory>

#include "mresim/mess/protocols/loading.hpp"
#include "mresim/mess/protocols/protocol.hpp"

namespace mresim::mess_protocol {
namespace {

class Magnetostriction final : public Protocol {
 public:
  [[nodiscard]] LoadState load(const lattice::Lattice& lattice, const StepSpec& /*step*/,
                               const Eigen::Matrix3Xd& reference) const override {
    return magnetostriction_load(lattice, reference);
  }
};

const ProtocolRegistrar magnetostriction_protocol_registrar(
    {"mess_magnetostriction",
     "3D lattice (MESS): field series with only the bottom face held",
     {},
     [](const config::TableReader& /*root*/) { return std::make_shared<const Magnetostriction>(); },
     mess_config::FieldSequence::up,
     3});

}  // namespace
}  // namespace mresim::mess_protocol
