// map_hdf5.cpp — map.h5: the map's points and boundary as HDF5 compound datasets, written in
// chunks into extendible datasets (Debian's libhdf5, C API), without time stamps so that the same
// map gives the same bytes (docs/design.md, "Design-space maps").
#include "map_store.hpp"

#include <hdf5.h>

#include <stdexcept>

namespace backlash::map::detail {

namespace {

constexpr hsize_t chunk_rows = 4096;

hid_t checked(hid_t id, const char* what) {
  if (id < 0) throw std::runtime_error(std::string("map.h5: HDF5 failed to ") + what);
  return id;
}
void checked(herr_t status, const char* what, int) {
  if (status < 0) throw std::runtime_error(std::string("map.h5: HDF5 failed to ") + what);
}

// A compound type of 8-byte fields, packed, built from names (a leading '#' marks an int64, '%' the status enum).
hid_t compound(const std::vector<std::string>& fields, hid_t status_type) {
  const hid_t type = checked(H5Tcreate(H5T_COMPOUND, 8 * fields.size()), "create a compound type");
  for (std::size_t k = 0; k < fields.size(); ++k) {
    const std::string& f = fields[k];
    const hid_t member = f[0] == '#' ? H5T_STD_I64LE : f[0] == '%' ? status_type : H5T_IEEE_F64LE;
    const std::string name = (f[0] == '#' || f[0] == '%') ? f.substr(1) : f;
    checked(H5Tinsert(type, name.c_str(), 8 * k, member), "insert a field", 0);
  }
  return type;
}

struct Table {
  hid_t dataset = -1, type = -1;
  std::size_t width = 0;  ///< fields
  hsize_t rows = 0;
  std::vector<char> buffer;  ///< rows not yet written
};

}  // namespace

struct MapHdf5::Impl {
  hid_t file = -1, status_type = -1;
  Table points, boundary;
  std::size_t d = 0;

  void open_table(Table& t, const char* name, const std::vector<std::string>& fields) {
    t.type = compound(fields, status_type);
    t.width = fields.size();
    const hsize_t zero = 0, unlimited = H5S_UNLIMITED;
    const hid_t space = checked(H5Screate_simple(1, &zero, &unlimited), "create a data space");
    const hid_t properties = checked(H5Pcreate(H5P_DATASET_CREATE), "create dataset properties");
    checked(H5Pset_chunk(properties, 1, &chunk_rows), "set the chunk size", 0);
    checked(H5Pset_obj_track_times(properties, false), "switch time stamps off", 0);
    t.dataset = checked(H5Dcreate2(file, name, t.type, space, H5P_DEFAULT, properties, H5P_DEFAULT), "create a dataset");
    H5Pclose(properties);
    H5Sclose(space);
  }

  void flush(Table& t) {
    const hsize_t count = t.buffer.size() / (8 * t.width);
    if (count == 0) return;
    const hsize_t total = t.rows + count;
    checked(H5Dset_extent(t.dataset, &total), "extend a dataset", 0);
    const hid_t file_space = checked(H5Dget_space(t.dataset), "get a data space");
    checked(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, &t.rows, nullptr, &count, nullptr), "select rows", 0);
    const hid_t memory_space = checked(H5Screate_simple(1, &count, nullptr), "create a data space");
    checked(H5Dwrite(t.dataset, t.type, memory_space, file_space, H5P_DEFAULT, t.buffer.data()), "write rows", 0);
    H5Sclose(memory_space);
    H5Sclose(file_space);
    t.rows = total;
    t.buffer.clear();
  }

  void append(Table& t, const void* row) {
    const char* bytes = static_cast<const char*>(row);
    t.buffer.insert(t.buffer.end(), bytes, bytes + 8 * t.width);
    if (t.buffer.size() >= 8 * t.width * chunk_rows) flush(t);
  }
};

MapHdf5::MapHdf5(const std::filesystem::path& path, const MapPlan& plan) : impl_(std::make_unique<Impl>()) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // failures are our one-line errors, not HDF5's stack dumps on stderr
  Impl& m = *impl_;
  m.d = plan.request().vary.size();
  const hid_t creation = checked(H5Pcreate(H5P_FILE_CREATE), "create file properties");
  checked(H5Pset_obj_track_times(creation, false), "switch time stamps off", 0);
  m.file = checked(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, creation, H5P_DEFAULT), "create the file");
  H5Pclose(creation);
  m.status_type = checked(H5Tenum_create(H5T_STD_I64LE), "create the status type");
  const auto& names = map_status_names();
  for (std::int64_t k = 0; k < static_cast<std::int64_t>(names.size()); ++k)
    checked(H5Tenum_insert(m.status_type, names[static_cast<std::size_t>(k)].c_str(), &k), "name a status", 0);
  std::vector<std::string> fields = {"#index", "%status"};
  std::vector<std::string> boundary = {"#along", "#lower", "#upper", "#appears"};
  for (const MapAxis& a : plan.request().vary) fields.push_back("x_" + a.name), boundary.push_back("x_" + a.name);
  for (const std::string& f : numeric::point_column_names()) fields.push_back(f);
  for (const char* f : {"peak_to_peak", "amplitude", "period", "separation_velocity", "multiplier", "settle_time"})
    fields.push_back(f);
  for (const char* f : {"bracket_low", "bracket_high", "#evaluations"}) boundary.push_back(f);
  m.open_table(m.points, "points", fields);
  m.open_table(m.boundary, "boundary", boundary);
}

MapHdf5::~MapHdf5() {
  try {
    close();
  } catch (...) {  // a destructor does not throw; close() is called explicitly on the success path
  }
}

void MapHdf5::add(const MapRecord& r) {
  std::vector<char> row(8 * (2 + r.values.size()));
  std::memcpy(row.data(), &r.index, 8);
  std::memcpy(row.data() + 8, &r.status, 8);
  std::memcpy(row.data() + 16, r.values.data(), 8 * r.values.size());
  impl_->append(impl_->points, row.data());
}

void MapHdf5::add_boundary(const MapBoundaryRow& b) {
  std::vector<char> row(8 * impl_->boundary.width);
  const std::int64_t head[4] = {b.along, b.lower, b.upper, b.kind.rfind("appears", 0) == 0 ? 1 : 0};
  std::memcpy(row.data(), head, sizeof head);
  std::memcpy(row.data() + 32, b.x.data(), 8 * b.x.size());
  const double bracket[2] = {b.low, b.high};
  std::memcpy(row.data() + 32 + 8 * b.x.size(), bracket, sizeof bracket);
  const std::int64_t evaluations = b.evaluations;
  std::memcpy(row.data() + 48 + 8 * b.x.size(), &evaluations, 8);
  impl_->append(impl_->boundary, row.data());
}

void MapHdf5::close() {
  Impl& m = *impl_;
  if (m.file < 0) return;
  for (Table* t : {&m.points, &m.boundary}) {
    m.flush(*t);
    H5Dclose(t->dataset);
    H5Tclose(t->type);
  }
  H5Tclose(m.status_type);
  const herr_t status = H5Fclose(m.file);
  m.file = -1;
  checked(status, "close the file", 0);
}

}  // namespace backlash::map::detail
