#include "store/camera_table.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdio>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <vector>

#include "core/error.hpp"
#include "store/atomic_file.hpp"
#include "store/safe_file.hpp"

namespace panoptes::store {

namespace fs = std::filesystem;

// ---- CRC-32, slicing by 8 (about 1.5-2 GB/s: the check costs ~5 ms for 10^6 cameras) ----------

namespace {

constexpr std::array<std::array<std::uint32_t, 256>, 8> make_crc_tables() {
  std::array<std::array<std::uint32_t, 256>, 8> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
    t[0][i] = c;
  }
  for (std::uint32_t i = 0; i < 256; ++i)
    for (std::size_t s = 1; s < 8; ++s) t[s][i] = (t[s - 1][i] >> 8) ^ t[0][t[s - 1][i] & 0xFF];
  return t;
}

constexpr auto kCrc = make_crc_tables();

}  // namespace

std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc) {
  const auto* p = static_cast<const unsigned char*>(data);
  crc = ~crc;
  while (size >= 8) {
    const std::uint32_t a = crc ^ (std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
                                   std::uint32_t(p[3]) << 24);
    crc = kCrc[7][a & 0xFF] ^ kCrc[6][(a >> 8) & 0xFF] ^ kCrc[5][(a >> 16) & 0xFF] ^ kCrc[4][a >> 24] ^
          kCrc[3][p[4]] ^ kCrc[2][p[5]] ^ kCrc[1][p[6]] ^ kCrc[0][p[7]];
    p += 8;
    size -= 8;
  }
  while (size--) crc = (crc >> 8) ^ kCrc[0][(crc ^ *p++) & 0xFF];
  return ~crc;
}

// ---- layout ----------------------------------------------------------------------------------
//
// Header (40 bytes): magic[8], u32 version, u32 crc32 of bytes [16, end), u64 file size, u64 camera
// count, u32 column count, u32 reserved (0). Then one 56-byte descriptor per column: name[24]
// (NUL-padded), u32 type, u32 components, u64 rows (1 = one value shared by every camera, else the
// camera count), u64 offset, u64 size. Column data follows at 8-byte aligned offsets. All integers and
// doubles are little-endian; doubles are IEEE 754 binary64.

namespace {

constexpr std::size_t kHeaderSize = 40, kColumnSize = 56, kNameSize = 24;
constexpr std::size_t kCrcOffset = 12, kCrcStart = 16;

enum class Type : std::uint32_t { f64 = 1, i32 = 2, u32 = 3, blob = 4 };

std::size_t element_size(Type t) { return t == Type::f64 ? 8 : t == Type::blob ? 1 : 4; }

// The table is little-endian on disk: a value's bytes are swapped on a big-endian host (both ways).
template <class T>
T little_endian(T v) {
  if constexpr (std::endian::native == std::endian::big) {
    if constexpr (sizeof(T) == 8) {
      std::uint64_t u;
      std::memcpy(&u, &v, 8);
      u = __builtin_bswap64(u);
      std::memcpy(&v, &u, 8);
    } else if constexpr (sizeof(T) == 4) {
      std::uint32_t u;
      std::memcpy(&u, &v, 4);
      u = __builtin_bswap32(u);
      std::memcpy(&v, &u, 4);
    }
  }
  return v;
}

template <class T>
T load(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return little_endian(v);
}

template <class T>
void store_le(std::string& out, std::size_t at, T v) {
  v = little_endian(v);
  std::memcpy(out.data() + at, &v, sizeof v);
}

template <class T>
void append_le(std::string& out, T v) {
  const std::size_t at = out.size();
  out.resize(at + sizeof v);
  store_le(out, at, v);
}

void append_string(std::string& out, const std::string& s) {
  append_le(out, std::uint32_t(s.size()));
  out += s;
}

// A column being built: its values for every camera, collapsed to one row if all rows are equal.
struct ColumnOut {
  std::string name;
  Type type;
  std::uint32_t components;
  std::uint64_t rows;
  std::string data;
};

template <class T, class Get>
ColumnOut fixed_column(std::string name, Type type, std::uint32_t components, std::size_t n, Get get) {
  ColumnOut c{std::move(name), type, components, n, {}};
  const std::size_t row = components * sizeof(T);
  c.data.resize(n * row);
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t k = 0; k < components; ++k) store_le<T>(c.data, i * row + k * sizeof(T), get(i, k));
  // Rigs often share look_at, up, fov and shell: one row then stands for all cameras.
  bool constant = n > 1;
  for (std::size_t i = 1; i < n && constant; ++i) constant = std::memcmp(c.data.data(), c.data.data() + i * row, row) == 0;
  if (constant) {
    c.rows = 1;
    c.data.resize(row);
  }
  return c;
}

double vec_component(const Vec3& v, std::uint32_t k) { return k == 0 ? v.x : k == 1 ? v.y : v.z; }

}  // namespace

std::string encode_camera_table(const Manifest& m) {
  const std::size_t n = m.cameras.size();
  const auto& cams = m.cameras;
  std::vector<ColumnOut> cols;
  cols.push_back(fixed_column<double>("position", Type::f64, 3, n, [&](std::size_t i, std::uint32_t k) {
    return vec_component(cams[i].position, k);
  }));
  cols.push_back(fixed_column<double>("look_at", Type::f64, 3, n, [&](std::size_t i, std::uint32_t k) {
    return vec_component(cams[i].look_at, k);
  }));
  cols.push_back(fixed_column<double>("up", Type::f64, 3, n, [&](std::size_t i, std::uint32_t k) {
    return vec_component(cams[i].up, k);
  }));
  cols.push_back(fixed_column<double>("fov_y_deg", Type::f64, 1, n, [&](std::size_t i, std::uint32_t) { return cams[i].fov_y_deg; }));
  cols.push_back(fixed_column<double>("lat_deg", Type::f64, 1, n, [&](std::size_t i, std::uint32_t) { return cams[i].labels.lat_deg; }));
  cols.push_back(fixed_column<double>("lon_deg", Type::f64, 1, n, [&](std::size_t i, std::uint32_t) { return cams[i].labels.lon_deg; }));
  cols.push_back(fixed_column<std::int32_t>("shell", Type::i32, 1, n, [&](std::size_t i, std::uint32_t) { return std::int32_t(cams[i].labels.shell); }));
  // Patch names are few ("yin", "yang", ...): a dictionary plus one index per camera.
  std::vector<std::string> names;
  std::vector<std::uint32_t> patch(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::string& p = cams[i].labels.patch;
    std::size_t k = 0;
    // Cameras of one patch are usually contiguous: try the previous camera's name first.
    if (i > 0 && names[patch[i - 1]] == p) {
      k = patch[i - 1];
    } else {
      while (k < names.size() && names[k] != p) ++k;
      if (k == names.size()) names.push_back(p);
    }
    patch[i] = std::uint32_t(k);
  }
  cols.push_back(fixed_column<std::uint32_t>("patch", Type::u32, 1, n, [&](std::size_t i, std::uint32_t) { return patch[i]; }));
  {
    ColumnOut c{"patch_names", Type::blob, 1, 1, {}};
    append_le(c.data, std::uint32_t(names.size()));
    for (const auto& s : names) append_string(c.data, s);
    cols.push_back(std::move(c));
  }
  {
    // Free-form labels are rare: only cameras that have some are listed.
    ColumnOut c{"extra", Type::blob, 1, 1, {}};
    std::uint32_t entries = 0;
    append_le(c.data, entries);
    for (std::size_t i = 0; i < n; ++i) {
      const auto& extra = cams[i].labels.extra;
      if (extra.empty()) continue;
      ++entries;
      append_le(c.data, std::uint32_t(i));
      append_le(c.data, std::uint32_t(extra.size()));
      for (const auto& [k, v] : extra) {
        append_string(c.data, k);
        append_string(c.data, v);
      }
    }
    store_le(c.data, 0, entries);
    cols.push_back(std::move(c));
  }
  if (!m.graph.neighbours.empty()) {
    const auto& g = m.graph.neighbours;
    auto col = fixed_column<std::int32_t>("neighbours", Type::i32, 6, g.size(), [&](std::size_t i, std::uint32_t k) {
      const Neighbours& e = g[i];
      const int v[6] = {e.left, e.right, e.up, e.down, e.in, e.out};
      return std::int32_t(v[k]);
    });
    cols.push_back(std::move(col));
  }

  std::string out(kHeaderSize + kColumnSize * cols.size(), '\0');
  std::memcpy(out.data(), kCameraTableMagic.data(), 8);
  store_le(out, 8, kCameraTableVersion);
  store_le(out, 24, std::uint64_t(n));
  store_le(out, 32, std::uint32_t(cols.size()));
  for (std::size_t c = 0; c < cols.size(); ++c) {
    out.resize((out.size() + 7) & ~std::size_t(7), '\0');
    const std::size_t d = kHeaderSize + c * kColumnSize;
    std::memcpy(out.data() + d, cols[c].name.data(), std::min(cols[c].name.size(), kNameSize - 1));
    store_le(out, d + 24, std::uint32_t(cols[c].type));
    store_le(out, d + 28, cols[c].components);
    store_le(out, d + 32, cols[c].rows);
    store_le(out, d + 40, std::uint64_t(out.size()));
    store_le(out, d + 48, std::uint64_t(cols[c].data.size()));
    out += cols[c].data;
  }
  store_le(out, 16, std::uint64_t(out.size()));
  store_le(out, kCrcOffset, crc32(out.data() + kCrcStart, out.size() - kCrcStart));
  return out;
}

// ---- decoding --------------------------------------------------------------------------------

namespace {

struct ColumnIn {
  Type type{};
  std::uint32_t components = 0;
  std::uint64_t rows = 0;
  const char* data = nullptr;
  std::uint64_t size = 0;
  bool present = false;
};

// Bounds-checked reading of a blob column.
struct BlobReader {
  const char* p;
  std::uint64_t left;
  const std::string& source;
  const char* column;

  [[noreturn]] void overrun() const {
    throw FileError(source, std::string("camera table column \"") + column + "\" is cut short (corrupt file)");
  }
  std::uint32_t u32() {
    if (left < 4) overrun();
    const auto v = load<std::uint32_t>(p);
    p += 4;
    left -= 4;
    return v;
  }
  std::string str() {
    const std::uint32_t len = u32();
    if (left < len) overrun();
    std::string s(p, len);
    p += len;
    left -= len;
    return s;
  }
};

}  // namespace

void decode_camera_table(std::string_view bytes, const CameraTableRef& expected, const std::string& source,
                         Manifest& m) {
  const auto fail = [&](const std::string& what) -> void { throw FileError(source, what); };
  const std::size_t size = bytes.size();
  if (size < 8 || bytes.substr(0, 8) != kCameraTableMagic)
    fail("not a Panoptes camera table (wrong magic bytes; expected \"PNPTCAMS\")");
  if (size < kHeaderSize)
    fail("camera table truncated: " + std::to_string(size) + " bytes, shorter than its " + std::to_string(kHeaderSize) +
         "-byte header");
  const char* base = bytes.data();
  const auto version = load<std::uint32_t>(base + 8);
  if (version != kCameraTableVersion)
    fail("camera table format version " + std::to_string(version) + " is not supported (this build reads version " +
         std::to_string(kCameraTableVersion) + (version > kCameraTableVersion ? "; written by a newer Panoptes)" : ")"));
  const auto recorded_size = load<std::uint64_t>(base + 16);
  if (recorded_size != size)
    fail("camera table truncated or padded: the file has " + std::to_string(size) + " bytes, its header records " +
         std::to_string(recorded_size));
  if (expected.bytes != size)
    fail("camera table has " + std::to_string(size) + " bytes, the manifest records " + std::to_string(expected.bytes) +
         " (table and manifest do not belong together)");
  const std::uint32_t header_crc = load<std::uint32_t>(base + kCrcOffset);
  const std::uint32_t crc = crc32(base + kCrcStart, size - kCrcStart);
  const auto hex = [](std::uint32_t v) { return camera_table_file_name(v).substr(8, 8); };
  if (crc != header_crc)
    fail("camera table checksum mismatch: the CRC-32 of its contents is " + hex(crc) + ", its header records " +
         hex(header_crc) + " (corrupt file)");
  if (crc != expected.crc32)
    fail("camera table checksum " + hex(crc) + " (its contents and header agree) differs from the " + hex(expected.crc32) +
         " the manifest records (table and manifest do not belong together)");
  const auto count = load<std::uint64_t>(base + 24);
  if (count != std::uint64_t(expected.cameras))
    fail("camera table holds " + std::to_string(count) + " cameras, the manifest records " +
         std::to_string(expected.cameras));
  if (count > std::uint64_t(kMaxCameras))
    fail("camera count " + std::to_string(count) + " is more than the limit of " + std::to_string(kMaxCameras));
  const auto ncols = load<std::uint32_t>(base + 32);
  if (std::uint64_t(ncols) * kColumnSize > size - kHeaderSize)
    fail("camera table column count " + std::to_string(ncols) + " does not fit the file");
  const std::uint64_t data_start = kHeaderSize + std::uint64_t(ncols) * kColumnSize;

  static constexpr const char* kKnown[] = {"position", "look_at", "up",          "fov_y_deg", "lat_deg", "lon_deg",
                                           "shell",    "patch",   "patch_names", "extra",     "neighbours"};
  constexpr std::size_t kKnownCount = std::size(kKnown);
  ColumnIn cols[kKnownCount];
  for (std::uint32_t c = 0; c < ncols; ++c) {
    const char* d = base + kHeaderSize + std::size_t(c) * kColumnSize;
    const std::string name(d, strnlen(d, kNameSize));
    const auto it = std::find_if(std::begin(kKnown), std::end(kKnown), [&](const char* k) { return name == k; });
    if (it == std::end(kKnown)) continue;  // a column added by a later version: ignored
    ColumnIn& col = cols[it - std::begin(kKnown)];
    const std::string at = "camera table column \"" + name + "\"";
    if (col.present) fail(at + " appears twice");
    col.present = true;
    col.type = Type(load<std::uint32_t>(d + 24));
    col.components = load<std::uint32_t>(d + 28);
    col.rows = load<std::uint64_t>(d + 32);
    const auto offset = load<std::uint64_t>(d + 40);
    col.size = load<std::uint64_t>(d + 48);
    if (offset < data_start || offset > size || col.size > size - offset)
      fail(at + ": bytes " + std::to_string(offset) + " + " + std::to_string(col.size) + " lie outside the file (" +
           std::to_string(size) + " bytes)");
    col.data = base + offset;
    if (col.type != Type::blob) {
      if (col.rows != count && !(col.rows == 1 && count > 0))
        fail(at + " has " + std::to_string(col.rows) + " rows, expected " + std::to_string(count) +
             " (one per camera) or 1 (shared)");
      if (col.components == 0 || col.components > 6 ||
          col.size != col.rows * col.components * element_size(col.type))
        fail(at + ": size " + std::to_string(col.size) + " does not match " + std::to_string(col.rows) + " rows of " +
             std::to_string(col.components) + " values");
    }
  }
  const auto column = [&](std::size_t index, Type type, std::uint32_t components) -> const ColumnIn& {
    const ColumnIn& col = cols[index];
    const std::string at = std::string("camera table column \"") + kKnown[index] + "\"";
    if (!col.present) fail(at + " is missing");
    if (col.type != type || (type != Type::blob && col.components != components))
      fail(at + " has type " + std::to_string(std::uint32_t(col.type)) + " with " + std::to_string(col.components) +
           " components, expected type " + std::to_string(std::uint32_t(type)) + " with " + std::to_string(components));
    return col;
  };
  const ColumnIn& position = column(0, Type::f64, 3);
  const ColumnIn& look_at = column(1, Type::f64, 3);
  const ColumnIn& up = column(2, Type::f64, 3);
  const ColumnIn& fov = column(3, Type::f64, 1);
  const ColumnIn& lat = column(4, Type::f64, 1);
  const ColumnIn& lon = column(5, Type::f64, 1);
  const ColumnIn& shell = column(6, Type::i32, 1);
  const ColumnIn& patch = column(7, Type::u32, 1);

  std::vector<std::string> names;
  {
    BlobReader r{column(8, Type::blob, 1).data, cols[8].size, source, "patch_names"};
    const std::uint32_t k = r.u32();
    if (k > r.left / 4) r.overrun();
    names.reserve(k);
    for (std::uint32_t i = 0; i < k; ++i) names.push_back(r.str());
  }

  const std::size_t n = std::size_t(count);
  m.cameras.clear();
  m.cameras.resize(n);
  // Row i of a column (row 0 for a shared one).
  const auto row = [](const ColumnIn& c, std::size_t i, std::size_t bytes) { return c.data + (c.rows == 1 ? 0 : i * bytes); };
  const auto vec = [](const char* p) { return Vec3{load<double>(p), load<double>(p + 8), load<double>(p + 16)}; };
  for (std::size_t i = 0; i < n; ++i) {
    CameraEntry& e = m.cameras[i];
    e.id = int(i);
    e.position = vec(row(position, i, 24));
    e.look_at = vec(row(look_at, i, 24));
    e.up = vec(row(up, i, 24));
    e.fov_y_deg = load<double>(row(fov, i, 8));
    e.labels.lat_deg = load<double>(row(lat, i, 8));
    e.labels.lon_deg = load<double>(row(lon, i, 8));
    e.labels.shell = load<std::int32_t>(row(shell, i, 4));
    const std::uint32_t p = load<std::uint32_t>(row(patch, i, 4));
    if (p >= names.size())
      fail("camera table: camera " + std::to_string(i) + " names patch " + std::to_string(p) + " of " +
           std::to_string(names.size()));
    e.labels.patch = names[p];
    // A JSON manifest cannot hold NaN or infinity; a binary one must not either.
    const double values[] = {e.position.x, e.position.y, e.position.z, e.look_at.x, e.look_at.y, e.look_at.z,
                             e.up.x,       e.up.y,       e.up.z,       e.labels.lat_deg, e.labels.lon_deg};
    for (double v : values)
      if (!std::isfinite(v)) fail("camera table: camera " + std::to_string(i) + " has a non-finite coordinate or label");
    if (!(e.fov_y_deg > 0 && e.fov_y_deg < 180))
      fail("camera table: camera " + std::to_string(i) + " fov_y_deg " + std::to_string(e.fov_y_deg) +
           " is not in (0, 180)");
    if (e.position == e.look_at) fail("camera table: camera " + std::to_string(i) + ": position equals look_at");
  }
  if (const ColumnIn& extra = cols[9]; extra.present) {
    column(9, Type::blob, 1);
    BlobReader r{extra.data, extra.size, source, "extra"};
    const std::uint32_t entries = r.u32();
    for (std::uint32_t k = 0; k < entries; ++k) {
      const std::uint32_t cam = r.u32(), pairs = r.u32();
      if (cam >= n)
        fail("camera table column \"extra\" names camera " + std::to_string(cam) + " (valid: 0.." +
             std::to_string(std::int64_t(n) - 1) + ")");
      auto& labels = m.cameras[cam].labels.extra;
      for (std::uint32_t q = 0; q < pairs; ++q) {
        std::string key = r.str();
        labels[std::move(key)] = r.str();
      }
    }
  }
  m.graph.neighbours.clear();
  if (cols[10].present) {
    const ColumnIn& g = column(10, Type::i32, 6);
    m.graph.neighbours.resize(n);
    const int last = int(n) - 1;
    for (std::size_t i = 0; i < n; ++i) {
      const char* p = row(g, i, 24);
      Neighbours& e = m.graph.neighbours[i];
      int* slots[] = {&e.left, &e.right, &e.up, &e.down, &e.in, &e.out};
      for (int k = 0; k < 6; ++k) {
        const std::int32_t v = load<std::int32_t>(p + 4 * k);
        if (v < -1 || v > last)
          fail("camera table: navigation graph entry " + std::to_string(i) + " names camera " + std::to_string(v) +
               " (valid: -1 or 0.." + std::to_string(last) + ")");
        *slots[k] = v;
      }
    }
  }
}

std::string camera_table_file_name(std::uint32_t crc) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "cameras.%08x.bin", crc);
  return buf;
}

void validate_camera_table_name(const std::string& name) {
  const auto bad = [&](const std::string& why) { throw Error("camera table file name \"" + name + "\" " + why); };
  if (name.rfind("cameras", 0) != 0 || name.size() < 11 || name.compare(name.size() - 4, 4, ".bin") != 0)
    bad("is not of the form cameras*.bin");
  for (char ch : name)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' || ch == '-'))
      bad("may only hold letters, digits, '.', '_' and '-'");
}

CameraTableRef write_camera_table(const fs::path& dir, const Manifest& manifest) {
  const std::string bytes = encode_camera_table(manifest);
  CameraTableRef ref;
  ref.crc32 = load<std::uint32_t>(bytes.data() + kCrcOffset);
  ref.file = camera_table_file_name(ref.crc32);
  ref.bytes = bytes.size();
  ref.cameras = std::int64_t(manifest.cameras.size());
  ref.navigation = !manifest.graph.neighbours.empty();
  write_file_atomic(dir / ref.file, bytes, "camera table");
  return ref;
}

void read_camera_table(const fs::path& dir, const CameraTableRef& ref, Manifest& manifest) {
  const std::string name = (dir / ref.file).string();
  // No link, FIFO or device; not larger than the manifest says (checked again by decode, which names
  // both sizes): a hostile table cannot make the reader load more than the manifest admits.
  const FileHandle dfd = open_directory(dir);
  const std::uint64_t limit = std::min<std::uint64_t>(ref.bytes, kMaxCameraTableBytes);
  std::string bytes;
  try {
    bytes = read_regular_file(dfd.get(), ref.file, limit, "camera table", dir);
  } catch (const FileError& e) {
    if (std::string(e.what()).find(" missing") != std::string::npos)
      throw FileError(name, "camera table missing (the manifest refers to it)");
    throw;
  }
  decode_camera_table(bytes, ref, name, manifest);
}

}  // namespace panoptes::store
