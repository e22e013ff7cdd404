// PCD v0.5-v0.7 reader (any field layout and encoding) and writer.
#include <cstring>
#include <sstream>

#include "scfloam/atomic_file.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/lzf.hpp"
#include "scfloam/io/point_cloud_file.hpp"

namespace scfloam {
namespace {

struct PcdHeader {
  std::vector<CloudField> fields;
  std::size_t point_step = 0;
  std::size_t width = 0, height = 1, points = 0;
  std::string data;          // ascii | binary | binary_compressed
  std::size_t data_begin = 0; // byte after the DATA line
};

std::vector<std::string> split_words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

std::size_t parse_count(const std::filesystem::path& path, const std::string& key, const std::string& word) {
  char* end = nullptr;
  const unsigned long long v = std::strtoull(word.c_str(), &end, 10);
  if (word.empty() || *end != '\0' || word[0] == '-')
    throw file_error(path, "PCD header: " + key + " `" + word + "` is not a count");
  return static_cast<std::size_t>(v);
}

PcdHeader parse_header(const std::filesystem::path& path, const std::string& bytes) {
  PcdHeader h;
  std::vector<std::string> names, sizes, types, counts;
  bool have_width = false, have_points = false;
  std::size_t pos = 0;
  while (pos < bytes.size()) {
    const std::size_t eol = bytes.find('\n', pos);
    const std::string line = bytes.substr(pos, eol == std::string::npos ? std::string::npos : eol - pos);
    pos = eol == std::string::npos ? bytes.size() : eol + 1;
    auto words = split_words(line);
    if (words.empty() || words[0][0] == '#') continue;
    const std::string key = words[0];
    words.erase(words.begin());
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    if (key == "FIELDS" || key == "COLUMNS") names = words;
    else if (key == "SIZE") sizes = words;
    else if (key == "TYPE") types = words;
    else if (key == "COUNT") counts = words;
    else if (key == "WIDTH" && words.size() == 1) h.width = parse_count(path, key, words[0]), have_width = true;
    else if (key == "HEIGHT" && words.size() == 1) h.height = parse_count(path, key, words[0]);
    else if (key == "POINTS" && words.size() == 1) h.points = parse_count(path, key, words[0]), have_points = true;
    else if (key == "DATA" && words.size() == 1) {
      h.data = words[0];
      h.data_begin = pos;
      break;
    } else {
      throw file_error(path, "not a PCD file (unexpected header line `" + line.substr(0, 60) + "`)");
    }
  }
  if (h.data.empty()) throw file_error(path, "not a PCD file (no DATA line in the header)");
  if (h.data != "ascii" && h.data != "binary" && h.data != "binary_compressed")
    throw file_error(path, "PCD: unknown DATA `" + h.data + "` (ascii, binary, binary_compressed)");
  if (names.empty()) throw file_error(path, "PCD header has no FIELDS");
  if (sizes.size() != names.size() || types.size() != names.size())
    throw file_error(path, "PCD header: FIELDS, SIZE and TYPE have different lengths");
  if (!counts.empty() && counts.size() != names.size())
    throw file_error(path, "PCD header: COUNT has a different length than FIELDS");
  if (!have_width) throw file_error(path, "PCD header has no WIDTH");
  if (!have_points) h.points = h.width * h.height;
  if (h.points != h.width * h.height)
    throw file_error(path, "PCD header: POINTS " + std::to_string(h.points) + " != WIDTH x HEIGHT");
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::size_t size = parse_count(path, "SIZE", sizes[i]);
    const auto type = field_type_from_pcd(types[i].size() == 1 ? types[i][0] : '?', size);
    if (!type) throw file_error(path, "PCD field `" + names[i] + "`: TYPE " + types[i] + " SIZE " + sizes[i] + " is not a number type");
    CloudField f{names[i], h.point_step, *type, counts.empty() ? 1 : parse_count(path, "COUNT", counts[i])};
    if (f.count == 0) throw file_error(path, "PCD field `" + names[i] + "` has COUNT 0");
    if (f.count > 1024) throw file_error(path, "PCD field `" + names[i] + "`: COUNT " + counts[i] + " is implausible");
    h.point_step += size * f.count;
    h.fields.push_back(f);
  }
  return h;
}

// ASCII rows packed into binary rows of the declared types, so one decoder serves all encodings.
std::vector<unsigned char> pack_ascii(const std::filesystem::path& path, const PcdHeader& h,
                                      const std::string& bytes) {
  std::vector<unsigned char> rows(h.points * h.point_step);
  const char* p = bytes.c_str() + h.data_begin;
  for (std::size_t i = 0; i < h.points; ++i) {
    for (const auto& f : h.fields) {
      for (std::size_t k = 0; k < f.count; ++k) {
        char* end = nullptr;
        const double v = std::strtod(p, &end);
        if (end == p)
          throw file_error(path, "PCD ascii data ends or is not a number at point " + std::to_string(i) +
                                     " of " + std::to_string(h.points) + " (truncated?)");
        store_field_value(rows.data() + i * h.point_step + f.offset + k * field_type_size(f.type), f.type, v);
        p = end;
      }
    }
  }
  return rows;
}

// binary_compressed stores each field's values for all points together (struct of arrays),
// which the readers' conversion takes as it is (append_columns).
std::vector<unsigned char> decompress_columns(const std::filesystem::path& path, const PcdHeader& h,
                                             const std::string& bytes) {
  if (bytes.size() < h.data_begin + 8) throw file_error(path, "PCD binary_compressed data is truncated (no sizes)");
  std::uint32_t packed = 0, unpacked = 0;
  std::memcpy(&packed, bytes.data() + h.data_begin, 4);
  std::memcpy(&unpacked, bytes.data() + h.data_begin + 4, 4);
  if (unpacked != h.points * h.point_step)
    throw file_error(path, "PCD binary_compressed: uncompressed size " + std::to_string(unpacked) +
                               " != POINTS x point size " + std::to_string(h.points * h.point_step));
  if (bytes.size() - h.data_begin - 8 < packed)
    throw file_error(path, "PCD binary_compressed data is truncated (" + std::to_string(bytes.size() - h.data_begin - 8) +
                               " of " + std::to_string(packed) + " compressed bytes)");
  auto columns = lzf_decompress(reinterpret_cast<const unsigned char*>(bytes.data()) + h.data_begin + 8, packed, unpacked);
  if (!columns) throw file_error(path, "PCD binary_compressed data is corrupt (LZF stream does not decode)");
  return std::move(*columns);
}

}  // namespace

PointCloudFile read_pcd(const std::filesystem::path& path) {
  const std::string bytes = read_file_bytes(path);
  const PcdHeader h = parse_header(path, bytes);
  PointCloudFile file;
  file.fields = h.fields;
  file.format = "PCD " + h.data;
  file.declared_points = h.points;
  PointLayout layout;
  try {
    layout = map_point_fields(h.fields);
  } catch (const Error& e) {
    throw file_error(path, e.what());
  }
  if (h.data == "binary") {
    const std::size_t have = bytes.size() - h.data_begin;
    const std::size_t need = h.points <= have / h.point_step ? h.points * h.point_step : have + 1;
    if (have < need)
      throw file_error(path, "PCD binary data is truncated (" + std::to_string(bytes.size() - h.data_begin) +
                                 " of " + std::to_string(need) + " bytes)");
    append_points(reinterpret_cast<const unsigned char*>(bytes.data()) + h.data_begin, h.points,
                  h.point_step, h.fields, layout, false, file.scan);
    return file;
  }
  // Bounds before any size product: a corrupt WIDTH must not overflow or allocate wildly.
  if (h.data == "ascii") {
    std::size_t values = 0;
    for (const auto& f : h.fields) values += f.count;
    if (h.points > (bytes.size() - h.data_begin + 1) / (2 * values))
      throw file_error(path, "PCD ascii data is truncated (too short for " + std::to_string(h.points) + " points)");
  } else if (h.points > 0xffffffffu / h.point_step) {
    throw file_error(path, "PCD binary_compressed: " + std::to_string(h.points) + " points exceed the format's 4 GiB");
  }
  if (h.data == "ascii") {
    const auto rows = pack_ascii(path, h, bytes);
    append_points(rows.data(), h.points, h.point_step, h.fields, layout, false, file.scan);
  } else {
    append_columns(decompress_columns(path, h, bytes).data(), h.points, h.fields, layout, file.scan);
  }
  return file;
}

void write_pcd(const std::filesystem::path& path, const std::vector<LidarPoint>& points,
               PcdEncoding encoding, bool with_ring_time) {
  std::vector<CloudField> fields = {{"x", 0, FieldType::kFloat32}, {"y", 4, FieldType::kFloat32},
                                    {"z", 8, FieldType::kFloat32}, {"intensity", 12, FieldType::kFloat32}};
  if (with_ring_time) {
    fields.push_back({"ring", 16, FieldType::kUint16});
    fields.push_back({"time", 18, FieldType::kFloat32});
  }
  const std::size_t step = with_ring_time ? 22 : 16;
  std::vector<unsigned char> rows(points.size() * step);
  for (std::size_t i = 0; i < points.size(); ++i) {
    unsigned char* r = rows.data() + i * step;
    const LidarPoint& p = points[i];
    store_field_value(r + 0, FieldType::kFloat32, p.x);
    store_field_value(r + 4, FieldType::kFloat32, p.y);
    store_field_value(r + 8, FieldType::kFloat32, p.z);
    store_field_value(r + 12, FieldType::kFloat32, p.intensity);
    if (with_ring_time) {
      store_field_value(r + 16, FieldType::kUint16, p.ring);
      store_field_value(r + 18, FieldType::kFloat32, p.time_s);
    }
  }
  const char* data_name[] = {"ascii", "binary", "binary_compressed"};
  write_file_atomic(path, [&](std::ostream& out) {
    out << "# .PCD v0.7 - Point Cloud Data file format (written by scfloam)\nVERSION 0.7\nFIELDS";
    for (const auto& f : fields) out << ' ' << f.name;
    out << "\nSIZE";
    for (const auto& f : fields) out << ' ' << field_type_size(f.type);
    out << "\nTYPE";
    for (const auto& f : fields) out << ' ' << (f.type == FieldType::kFloat32 ? 'F' : 'U');
    out << "\nCOUNT";
    for (std::size_t k = 0; k < fields.size(); ++k) out << " 1";
    out << "\nWIDTH " << points.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points.size()
        << "\nDATA " << data_name[static_cast<int>(encoding)] << "\n";
    if (encoding == PcdEncoding::kAscii) {
      out.precision(9);
      for (const auto& p : points) {
        out << p.x << ' ' << p.y << ' ' << p.z << ' ' << p.intensity;
        if (with_ring_time) out << ' ' << p.ring << ' ' << p.time_s;
        out << '\n';
      }
    } else if (encoding == PcdEncoding::kBinary) {
      out.write(reinterpret_cast<const char*>(rows.data()), static_cast<std::streamsize>(rows.size()));
    } else {
      std::vector<unsigned char> columns(rows.size());
      std::size_t column_begin = 0;
      for (const auto& f : fields) {
        const std::size_t width = field_type_size(f.type);
        for (std::size_t i = 0; i < points.size(); ++i)
          std::memcpy(columns.data() + column_begin + i * width, rows.data() + i * step + f.offset, width);
        column_begin += width * points.size();
      }
      const auto packed = lzf_compress(columns.data(), columns.size());
      const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(packed.size()),
                                      static_cast<std::uint32_t>(columns.size())};
      out.write(reinterpret_cast<const char*>(sizes), sizeof sizes);
      out.write(reinterpret_cast<const char*>(packed.data()), static_cast<std::streamsize>(packed.size()));
    }
  });
}

}  // namespace scfloam
