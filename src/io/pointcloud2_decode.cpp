// Wire decoders of sensor_msgs/PointCloud2 (ROS 1 serialization and ROS 2 CDR).
#include "cdr.hpp"
#include "scfloam/io/pointcloud2.hpp"

namespace scfloam {
namespace {

// The body after the header is laid out identically in both generations.
void read_cloud_body(WireReader& in, PointCloud2View& cloud) {
  cloud.height = in.read<std::uint32_t>("height");
  cloud.width = in.read<std::uint32_t>("width");
  const std::uint32_t n_fields = in.read<std::uint32_t>("fields length");
  // Each field takes at least 13 bytes: refuse counts the message cannot hold.
  if (n_fields > in.remaining() / 13)
    in.fail("PointCloud2 claims " + std::to_string(n_fields) + " fields, more than the message holds");
  cloud.fields.resize(n_fields);
  for (PointField& f : cloud.fields) {
    f.name = in.read_string("field name");
    f.offset = in.read<std::uint32_t>("field offset");
    f.datatype = in.read<std::uint8_t>("field datatype");
    f.count = in.read<std::uint32_t>("field count");
  }
  cloud.is_bigendian = in.read<std::uint8_t>("is_bigendian") != 0;
  cloud.point_step = in.read<std::uint32_t>("point_step");
  cloud.row_step = in.read<std::uint32_t>("row_step");
  const std::uint32_t n_data = in.read<std::uint32_t>("data length");
  cloud.data = in.take(n_data, "data");
  cloud.data_size = n_data;
  // Some writers end the message before is_dense; it is informational only.
  cloud.is_dense = in.remaining() > 0 ? in.read<std::uint8_t>("is_dense") != 0 : false;
}

}  // namespace

PointCloud2View decode_ros1_pointcloud2(const std::uint8_t* bytes, std::size_t size,
                                        const std::string& where) {
  WireReader in(bytes, size, 0, /*big_endian=*/false, /*aligned=*/false, where);
  PointCloud2View cloud;
  in.read<std::uint32_t>("header.seq");
  cloud.stamp_sec = in.read<std::uint32_t>("header.stamp.sec");
  cloud.stamp_nanosec = in.read<std::uint32_t>("header.stamp.nsec");
  cloud.frame_id = in.read_string("header.frame_id");
  read_cloud_body(in, cloud);
  return cloud;
}

PointCloud2View decode_cdr_pointcloud2(const std::uint8_t* bytes, std::size_t size,
                                       const std::string& where) {
  if (size < 4) throw Error(where + ": CDR message of " + std::to_string(size) + " bytes has no encapsulation header");
  // Encapsulation kind: 0x0000 CDR big-endian, 0x0001 CDR little-endian (XCDR1, plain).
  const int kind = (bytes[0] << 8) | bytes[1];
  if (kind != 0 && kind != 1)
    throw Error(where + ": unsupported CDR encapsulation kind " + std::to_string(kind) +
                " (only plain CDR, little or big endian, is read)");
  WireReader in(bytes, size, 4, /*big_endian=*/kind == 0, /*aligned=*/true, where);
  PointCloud2View cloud;
  cloud.stamp_sec = in.read<std::int32_t>("header.stamp.sec");
  cloud.stamp_nanosec = in.read<std::uint32_t>("header.stamp.nanosec");
  cloud.frame_id = in.read_string("header.frame_id");
  read_cloud_body(in, cloud);
  return cloud;
}

}  // namespace scfloam
