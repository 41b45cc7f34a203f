#include "mresim/mess/outputs/xdmf_outputs.hpp"

#include <fmt/format.h>

#include <fstream>
#include <stdexcept>
#include <string>

#include "mresim/mess/outputs/mess_outputs.hpp"
#include "mresim/mess/protocols/protocol.hpp"
#include "mresim/mess/protocols/step_plan.hpp"

namespace mresim::mess_protocol {

namespace fs = std::filesystem;

namespace {

// What one grid shows besides its data: the step and the Time value it is filed under.
struct XdmfFrame {
  const StepRecord* record;
  std::size_t row;  // position in /steps
  double time;
  double field_projection;
};

// How one file refers to the run directory's files ("" from the run directory, "../" from
// xdmf/).
struct XdmfFileContext {
  std::string root;
  std::size_t steps = 0;      // S (rows of /steps)
  std::size_t particles = 0;  // N_p
  std::size_t nodes = 0;
  std::size_t cells = 0;
  std::string load_name;  // "load_rad", "load_1", "load_Pa"; "" for runs without a load
};

std::string hdf_item(const std::string& dims, const char* number_type, const std::string& source) {
  return fmt::format(
      "<DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"8\" "
      "Format=\"HDF\">{}</DataItem>",
      dims, number_type, source);
}

// Row `row` of an S x N_p (x 3) dataset of results.h5.
std::string step_slab(const XdmfFileContext& c, std::size_t row, const char* dataset,
                      const char* number_type, bool vector) {
  const std::string slab_dims =
      vector ? fmt::format("1 {} 3", c.particles) : fmt::format("1 {}", c.particles);
  const std::string selection = vector ? fmt::format("{} 0 0 1 1 1 1 {} 3", row, c.particles)
                                       : fmt::format("{} 0 1 1 1 {}", row, c.particles);
  const std::string source_dims = vector ? fmt::format("{} {} 3", c.steps, c.particles)
                                         : fmt::format("{} {}", c.steps, c.particles);
  return fmt::format(
      "<DataItem ItemType=\"HyperSlab\" Dimensions=\"{}\">\n"
      "      <DataItem Dimensions=\"3 {}\" Format=\"XML\">{}</DataItem>\n      {}\n"
      "     </DataItem>",
      slab_dims, vector ? 3 : 2, selection,
      hdf_item(source_dims, number_type, c.root + "results.h5:/steps/" + dataset));
}

// The step's values as grid attributes (ParaView: field data, e.g. for Annotate Attribute Data).
std::string grid_values(const XdmfFileContext& c, const XdmfFrame& f) {
  const StepRecord& r = *f.record;
  std::string out;
  const auto scalar = [&](const std::string& name, double value) {
    out += fmt::format(
        "    <Attribute Name=\"{}\" AttributeType=\"Scalar\" Center=\"Grid\">\n"
        "     <DataItem Dimensions=\"1\" Format=\"XML\">{}</DataItem>\n    </Attribute>\n",
        name, value);
  };
  scalar("step", static_cast<double>(r.step.index));
  scalar("field_along_T", f.field_projection);
  if (!c.load_name.empty()) scalar(c.load_name, r.step.load_value);
  out += fmt::format(
      "    <Attribute Name=\"field_T\" AttributeType=\"Vector\" Center=\"Grid\">\n"
      "     <DataItem Dimensions=\"1 3\" Format=\"XML\">{} {} {}</DataItem>\n    </Attribute>\n",
      r.step.field.x(), r.step.field.y(), r.step.field.z());
  return out;
}

std::string lattice_grid(const XdmfFileContext& c, const XdmfFrame& f) {
  const std::size_t s = f.record->step.index;
  const std::string positions = c.root + step_positions_file("", s).string();
  return fmt::format("   <Grid Name=\"step_{}\" GridType=\"Uniform\">\n", s) +
         fmt::format("    <Time Value=\"{}\"/>\n", f.time) +
         fmt::format("    <Topology TopologyType=\"Hexahedron\" NumberOfElements=\"{}\">\n",
                     c.cells) +
         "     " +
         hdf_item(fmt::format("{} 8", c.cells), "Int", c.root + "results.h5:/lattice/cells") +
         "\n    </Topology>\n    <Geometry GeometryType=\"XYZ\">\n     " +
         hdf_item(fmt::format("{} 3", c.nodes), "Float", positions + ":/positions") +
         "\n    </Geometry>\n"
         "    <Attribute Name=\"displacement\" AttributeType=\"Vector\" Center=\"Node\">\n     " +
         hdf_item(fmt::format("{} 3", c.nodes), "Float", positions + ":/displacement") +
         "\n    </Attribute>\n"
         "    <Attribute Name=\"material_id\" AttributeType=\"Scalar\" Center=\"Cell\">\n     " +
         hdf_item(fmt::to_string(c.cells), "Int", c.root + "results.h5:/lattice/cell_material") +
         "\n    </Attribute>\n"
         "    <Attribute Name=\"particle_id\" AttributeType=\"Scalar\" Center=\"Node\">\n     " +
         hdf_item(fmt::to_string(c.nodes), "Int", c.root + "results.h5:/lattice/particle_id") +
         "\n    </Attribute>\n" + grid_values(c, f) + "   </Grid>\n";
}

std::string particles_grid(const XdmfFileContext& c, const XdmfFrame& f) {
  const std::size_t s = f.record->step.index;
  return fmt::format("   <Grid Name=\"particles_step_{}\" GridType=\"Uniform\">\n", s) +
         fmt::format("    <Time Value=\"{}\"/>\n", f.time) +
         fmt::format(
             "    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" "
             "NodesPerElement=\"1\"/>\n",
             c.particles) +
         "    <Geometry GeometryType=\"XYZ\">\n     " +
         step_slab(c, f.row, "centres", "Float", true) +
         "\n    </Geometry>\n"
         "    <Attribute Name=\"magnetization\" AttributeType=\"Vector\" Center=\"Node\">\n     " +
         step_slab(c, f.row, "magnetization", "Float", true) +
         "\n    </Attribute>\n"
         "    <Attribute Name=\"cluster_id\" AttributeType=\"Scalar\" Center=\"Node\">\n     " +
         step_slab(c, f.row, "cluster_id", "Int", false) + "\n    </Attribute>\n" +
         grid_values(c, f) + "   </Grid>\n";
}

template <typename Grid>
void write_file(const fs::path& file, const XdmfFileContext& c,
                const std::vector<XdmfFrame>& frames, const char* name, Grid grid) {
  std::ofstream out(file);
  out << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
      << fmt::format("  <Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
                     name);
  for (const XdmfFrame& f : frames) out << grid(c, f);
  out << "  </Grid>\n </Domain>\n</Xdmf>\n";
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

// Splits `order` (positions in records) into stretches along which time strictly increases or
// decreases; a turning point ends its stretch.
void split_monotone(const std::vector<std::size_t>& order, const std::vector<double>& time,
                    std::vector<std::vector<std::size_t>>& legs) {
  std::vector<std::size_t> leg;
  int direction = 0;  // +1 rising, -1 falling, 0 not yet known
  for (const std::size_t i : order) {
    if (!leg.empty()) {
      const double previous = time[leg.back()];
      const int step = time[i] > previous ? 1 : (time[i] < previous ? -1 : 0);
      if (step == 0 || (direction != 0 && step != direction)) {
        legs.push_back(std::move(leg));
        leg.clear();
        direction = 0;
      } else {
        direction = step;
      }
    }
    leg.push_back(i);
  }
  if (!leg.empty()) legs.push_back(std::move(leg));
}

}  // namespace

std::vector<std::vector<std::size_t>> xdmf_legs(const std::vector<StepRecord>& records,
                                                const std::vector<double>& field_projection,
                                                bool has_load) {
  std::vector<std::vector<std::size_t>> legs;
  if (!has_load) {
    std::vector<std::size_t> all(records.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    split_monotone(all, field_projection, legs);
    return legs;
  }
  std::vector<double> load(records.size());
  std::vector<std::vector<std::size_t>> per_field;
  for (std::size_t i = 0; i < records.size(); ++i) {
    load[i] = records[i].step.load_value;
    const std::size_t f = records[i].step.field_index;
    if (per_field.size() <= f) per_field.resize(f + 1);
    per_field[f].push_back(i);
  }
  for (const std::vector<std::size_t>& steps : per_field) split_monotone(steps, load, legs);
  return legs;
}

void write_xdmf_views(const fs::path& run_dir, const ProtocolRunner& runner,
                      const std::vector<StepRecord>& records,
                      const std::vector<double>& field_projection) {
  const mess_config::MessSpec& spec = runner.spec();
  const lattice::Lattice& lat = runner.system().lattice();
  const bool lattice = spec.output.node_positions;
  const bool particles = runner.system().particle_count() > 0;
  const bool has_load = spec.protocol->has_load();
  XdmfFileContext top{"",
                      records.size(),
                      runner.system().particle_count(),
                      static_cast<std::size_t>(lat.node_count()),
                      static_cast<std::size_t>(lat.cell_count()),
                      has_load ? std::string("load_") + load_unit(spec) : std::string()};

  std::vector<XdmfFrame> by_step;
  for (std::size_t i = 0; i < records.size(); ++i) {
    by_step.push_back(
        {&records[i], i, static_cast<double>(records[i].step.index), field_projection[i]});
  }
  if (lattice) write_file(run_dir / "mess.xdmf", top, by_step, "lattice", lattice_grid);
  if (particles) write_file(run_dir / "particles.xdmf", top, by_step, "particles", particles_grid);
  if (!lattice && !particles) return;

  XdmfFileContext leg_context = top;
  leg_context.root = "../";
  fs::create_directories(run_dir / "xdmf");
  const auto legs = xdmf_legs(records, field_projection, has_load);
  for (std::size_t k = 0; k < legs.size(); ++k) {
    std::vector<XdmfFrame> frames;
    for (const std::size_t i : legs[k]) {
      frames.push_back({&records[i], i, has_load ? records[i].step.load_value : field_projection[i],
                        field_projection[i]});
    }
    const std::string leg = fmt::format("leg_{:02d}.xdmf", k);
    if (lattice) {
      write_file(run_dir / "xdmf" / ("lattice_" + leg), leg_context, frames, "lattice",
                 lattice_grid);
    }
    if (particles) {
      write_file(run_dir / "xdmf" / ("particles_" + leg), leg_context, frames, "particles",
                 particles_grid);
    }
  }
}

}  // namespace mresim::mess_protocol
