// PLY reader (ascii, binary little/big endian; the vertex element with any scalar properties)
// and writer (x y z intensity).
#include <algorithm>
#include <cstring>
#include <sstream>

#include "scfloam/atomic_file.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/point_cloud_file.hpp"

namespace scfloam {
namespace {

struct PlyProperty {
  std::string name;
  FieldType type = FieldType::kFloat32;
  bool is_list = false;
  FieldType list_count_type = FieldType::kUint8;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  std::string format;  // ascii | binary_little_endian | binary_big_endian
  std::vector<PlyElement> elements;
  std::size_t data_begin = 0;
};

PlyHeader parse_header(const std::filesystem::path& path, const std::string& bytes) {
  if (bytes.compare(0, 3, "ply") != 0) throw file_error(path, "not a PLY file (does not start with `ply`)");
  PlyHeader h;
  std::size_t pos = 0;
  while (true) {
    const std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) throw file_error(path, "PLY header has no end_header line (truncated?)");
    std::string line = bytes.substr(pos, eol - pos);
    pos = eol + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream in(line);
    std::string key;
    in >> key;
    if (key == "end_header") break;
    if (key == "ply" || key == "comment" || key == "obj_info" || key.empty()) continue;
    if (key == "format") {
      in >> h.format;
    } else if (key == "element") {
      PlyElement e;
      if (!(in >> e.name >> e.count)) throw file_error(path, "PLY header: bad line `" + line + "`");
      h.elements.push_back(e);
    } else if (key == "property") {
      if (h.elements.empty()) throw file_error(path, "PLY header: property before any element");
      PlyProperty p;
      std::string type;
      in >> type;
      if (type == "list") {
        std::string count_type;
        in >> count_type >> type;
        const auto ct = field_type_from_ply(count_type);
        if (!ct) throw file_error(path, "PLY header: unknown type `" + count_type + "`");
        p.is_list = true;
        p.list_count_type = *ct;
      }
      const auto t = field_type_from_ply(type);
      if (!t || !(in >> p.name)) throw file_error(path, "PLY header: bad property line `" + line + "`");
      p.type = *t;
      h.elements.back().properties.push_back(p);
    } else {
      throw file_error(path, "PLY header: unexpected line `" + line.substr(0, 60) + "`");
    }
  }
  if (h.format != "ascii" && h.format != "binary_little_endian" && h.format != "binary_big_endian")
    throw file_error(path, "PLY: unknown format `" + h.format + "`");
  h.data_begin = pos;
  return h;
}

// Skips one element's rows of binary data (list properties have a count prefix each).
std::size_t skip_binary_element(const std::filesystem::path& path, const PlyElement& e, const std::string& bytes,
                                std::size_t pos, bool big_endian) {
  if (e.properties.empty()) return pos;  // rows of no bytes (a huge count must not loop)
  for (std::size_t i = 0; i < e.count; ++i) {
    for (const auto& p : e.properties) {
      std::size_t items = 1;
      if (p.is_list) {
        const std::size_t cs = field_type_size(p.list_count_type);
        if (pos + cs > bytes.size()) throw file_error(path, "PLY data is truncated in element `" + e.name + "`");
        unsigned char count_bytes[8] = {};
        std::memcpy(count_bytes, bytes.data() + pos, cs);
        if (big_endian) std::reverse(count_bytes, count_bytes + cs);
        std::uint64_t n = 0;
        for (std::size_t b = cs; b-- > 0;) n = n << 8 | count_bytes[b];
        items = static_cast<std::size_t>(n);
        pos += cs;
      }
      pos += items * field_type_size(p.type);
      if (pos > bytes.size()) throw file_error(path, "PLY data is truncated in element `" + e.name + "`");
    }
  }
  return pos;
}

}  // namespace

PointCloudFile read_ply(const std::filesystem::path& path) {
  const std::string bytes = read_file_bytes(path);
  const PlyHeader h = parse_header(path, bytes);
  const auto vertex = std::find_if(h.elements.begin(), h.elements.end(),
                                   [](const PlyElement& e) { return e.name == "vertex"; });
  if (vertex == h.elements.end()) throw file_error(path, "PLY has no vertex element");
  PointCloudFile file;
  file.format = "PLY " + h.format;
  file.declared_points = vertex->count;
  std::size_t step = 0;
  for (const auto& p : vertex->properties) {
    if (p.is_list) throw file_error(path, "PLY vertex property `" + p.name + "` is a list (not a point cloud)");
    file.fields.push_back({p.name, step, p.type, 1});
    step += field_type_size(p.type);
  }
  PointLayout layout;
  try {
    layout = map_point_fields(file.fields);
  } catch (const Error& e) {
    throw file_error(path, e.what());
  }
  const bool big_endian = h.format == "binary_big_endian";
  if (h.format == "ascii") {
    // Skip earlier elements line by line (one row per line), then pack the vertex rows.
    const char* p = bytes.c_str() + h.data_begin;
    for (auto e = h.elements.begin(); e != vertex; ++e)
      for (std::size_t i = 0; i < e->count; ++i) {
        p = std::strchr(p, '\n');
        if (!p) throw file_error(path, "PLY ascii data is truncated in element `" + e->name + "`");
        ++p;
      }
    if (vertex->count > (bytes.size() - static_cast<std::size_t>(p - bytes.c_str()) + 1) / (2 * file.fields.size()))
      throw file_error(path, "PLY ascii data is truncated (too short for " + std::to_string(vertex->count) + " vertices)");
    std::vector<unsigned char> rows(vertex->count * step);
    for (std::size_t i = 0; i < vertex->count; ++i)
      for (const auto& f : file.fields) {
        char* end = nullptr;
        const double v = std::strtod(p, &end);
        if (end == p)
          throw file_error(path, "PLY ascii data ends or is not a number at vertex " + std::to_string(i) +
                                     " of " + std::to_string(vertex->count) + " (truncated?)");
        store_field_value(rows.data() + i * step + f.offset, f.type, v);
        p = end;
      }
    append_points(rows.data(), vertex->count, step, file.fields, layout, false, file.scan);
    return file;
  }
  std::size_t pos = h.data_begin;
  for (auto e = h.elements.begin(); e != vertex; ++e) pos = skip_binary_element(path, *e, bytes, pos, big_endian);
  if (vertex->count > (bytes.size() - pos) / step)
    throw file_error(path, "PLY binary data is truncated (" + std::to_string(bytes.size() - pos) + " of " +
                               std::to_string(vertex->count * step) + " vertex bytes)");
  append_points(reinterpret_cast<const unsigned char*>(bytes.data()) + pos, vertex->count, step, file.fields,
                layout, big_endian, file.scan);
  return file;
}

void write_ply(const std::filesystem::path& path, const std::vector<LidarPoint>& points, PlyEncoding encoding) {
  const char* format[] = {"ascii", "binary_little_endian", "binary_big_endian"};
  write_file_atomic(path, [&](std::ostream& out) {
    out << "ply\nformat " << format[static_cast<int>(encoding)] << " 1.0\ncomment written by scfloam\n"
        << "element vertex " << points.size() << "\nproperty float x\nproperty float y\nproperty float z\n"
        << "property float intensity\nend_header\n";
    if (encoding == PlyEncoding::kAscii) {
      out.precision(9);
      for (const auto& p : points) out << p.x << ' ' << p.y << ' ' << p.z << ' ' << p.intensity << '\n';
      return;
    }
    const std::uint16_t one = 1;
    unsigned char first;
    std::memcpy(&first, &one, 1);
    const bool swap = (encoding == PlyEncoding::kBinaryBigEndian) == (first == 1);
    std::vector<unsigned char> rows(points.size() * 16);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const float v[4] = {points[i].x, points[i].y, points[i].z, points[i].intensity};
      std::memcpy(rows.data() + 16 * i, v, 16);
      if (swap)
        for (int k = 0; k < 4; ++k) std::reverse(rows.data() + 16 * i + 4 * k, rows.data() + 16 * i + 4 * k + 4);
    }
    out.write(reinterpret_cast<const char*>(rows.data()), static_cast<std::streamsize>(rows.size()));
  });
}

}  // namespace scfloam
