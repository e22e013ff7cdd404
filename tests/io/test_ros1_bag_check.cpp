// The walk that runs before librosbag (src/io/ros1_bag_check*.cpp): hand-made bags, valid ones
// read by librosbag itself, and one broken thing each, refused by us with the file named, before
// librosbag trusts it; real bags pass untouched.
#include <bzlib.h>
#include <gtest/gtest.h>
#include <lz4frame.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <fstream>
#include <functional>

#include "io/ros1_bag_check.hpp"
#include "scfloam/error.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace {

std::string u32(std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }
std::string u64(std::uint64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); }
std::string field(const std::string& name, const std::string& value) {
  return u32(static_cast<std::uint32_t>(name.size() + 1 + value.size())) + name + "=" + value;
}
std::string record(const std::string& header, const std::string& data) {
  return u32(static_cast<std::uint32_t>(header.size())) + header + u32(static_cast<std::uint32_t>(data.size())) + data;
}
std::string op(std::uint8_t v) { return field("op", std::string(1, static_cast<char>(v))); }

std::string compress(const std::string& raw, const std::string& how) {
  if (how == "none") return raw;
  std::string out(raw.size() * 2 + 1024, '\0');
  if (how == "bz2") {
    unsigned len = static_cast<unsigned>(out.size());
    EXPECT_EQ(BZ2_bzBuffToBuffCompress(out.data(), &len, const_cast<char*>(raw.data()),
                                       static_cast<unsigned>(raw.size()), 9, 0, 0), BZ_OK);
    out.resize(len);
  } else {
    // ROS's roslz4 reads only independent blocks with a content checksum.
    LZ4F_preferences_t prefs{};
    prefs.frameInfo.blockMode = LZ4F_blockIndependent;
    prefs.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
    prefs.frameInfo.blockSizeID = LZ4F_max64KB;
    const std::size_t len = LZ4F_compressFrame(out.data(), out.size(), raw.data(), raw.size(), &prefs);
    EXPECT_FALSE(LZ4F_isError(len));
    out.resize(len);
  }
  return out;
}

// What to build, and the one thing to break (defaults build a valid bag).
struct Knobs {
  std::string compression = "none";
  std::uint32_t index_conn = 0;            // connection an index record names
  std::int64_t index_offset_delta = 0;     // added to the message record's offset in the chunk
  std::uint32_t index_count_extra = 0;     // index "count" beyond its entries
  std::uint32_t info_count_extra = 0;      // chunk-info "count" beyond its entries
  std::int64_t size_delta = 0;             // chunk "size" minus the real uncompressed size
  std::uint32_t conn_count_extra = 0;      // bag header's conn_count beyond the records
  std::string encryptor;                   // bag header field, if set
  std::uint32_t message_data_extra = 0;    // message record's data length beyond its bytes
  std::function<void(std::string&)> mangle_compressed;  // applied to the stored chunk bytes
};

const std::string kConnectionHeader =
    field("type", "std_msgs/String") + field("md5sum", "992ce8a1687cec8c8bd883ec73ca41d1") +
    field("message_definition", "string data\n") + field("topic", "/chatter");

std::string make_bag(const Knobs& k) {
  const std::string connection = record(op(0x07) + field("conn", u32(0)) + field("topic", "/chatter"), kConnectionHeader);
  const std::string message_header = op(0x02) + field("conn", u32(0)) + field("time", u64(5));
  const std::string text = "hello";
  const std::string payload = u32(static_cast<std::uint32_t>(text.size())) + text;  // std_msgs/String
  std::string message = record(message_header, payload);
  if (k.message_data_extra)  // the data length claims more than the record holds
    message.replace(4 + message_header.size(), 4, u32(static_cast<std::uint32_t>(payload.size() + k.message_data_extra)));
  const std::string raw = connection + message;
  const std::uint32_t message_offset = static_cast<std::uint32_t>(connection.size());
  std::string stored = compress(raw, k.compression);
  if (k.mangle_compressed) k.mangle_compressed(stored);

  std::string bag = "#ROSBAG V2.0\n";
  const std::size_t header_pos = bag.size();
  auto file_header = [&](std::uint64_t index_pos) {
    std::string h = op(0x03) + field("index_pos", u64(index_pos)) + field("conn_count", u32(1 + k.conn_count_extra)) +
                    field("chunk_count", u32(1));
    if (!k.encryptor.empty()) h += field("encryptor", k.encryptor);
    return record(h, std::string(4096 - 8 - h.size(), ' '));
  };
  bag += file_header(0);
  const std::uint64_t chunk_pos = bag.size();
  const std::int64_t size = static_cast<std::int64_t>(raw.size()) + k.size_delta;
  bag += record(op(0x05) + field("compression", k.compression) + field("size", u32(static_cast<std::uint32_t>(size))), stored);
  const std::uint32_t offset = static_cast<std::uint32_t>(message_offset + k.index_offset_delta);
  bag += record(op(0x04) + field("ver", u32(1)) + field("conn", u32(k.index_conn)) + field("count", u32(1 + k.index_count_extra)),
                u32(5) + u32(0) + u32(offset));
  const std::uint64_t index_pos = bag.size();
  bag += connection;
  bag += record(op(0x06) + field("ver", u32(1)) + field("chunk_pos", u64(chunk_pos)) + field("start_time", u64(5)) +
                    field("end_time", u64(5)) + field("count", u32(1 + k.info_count_extra)),
                u32(0) + u32(1));
  bag.replace(header_pos, file_header(index_pos).size(), file_header(index_pos));
  return bag;
}

fs::path write_bag(const std::string& bytes, const std::string& name) {
  const fs::path path = scfloam::test::scratch_dir("ros1_bag_check") / (name + ".bag");
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

// The walk refuses the bag with an Error naming the file and containing `problem`.
void expect_refused(const Knobs& k, const std::string& problem) {
  const fs::path path = write_bag(make_bag(k), "broken");
  try {
    scfloam::check_ros1_bag_records(path);
    ADD_FAILURE() << "accepted; expected: " << problem;
  } catch (const scfloam::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(problem), std::string::npos) << what;
    EXPECT_NE(what.find(path.string()), std::string::npos) << what;
  }
}

}  // namespace

TEST(Ros1BagCheck, HandMadeBagsPassAndLibrosbagReadsThem) {
  for (const std::string compression : {"none", "bz2", "lz4"}) {
    SCOPED_TRACE(compression);
    Knobs k;
    k.compression = compression;
    const fs::path path = write_bag(make_bag(k), "valid-" + compression);
    EXPECT_NO_THROW(scfloam::check_ros1_bag_records(path));
    rosbag::Bag bag(path.string(), rosbag::bagmode::Read);
    rosbag::View view(bag);
    ASSERT_EQ(view.size(), 1u);
    for (const rosbag::MessageInstance& m : view) {
      EXPECT_EQ(m.getTopic(), "/chatter");
      EXPECT_EQ(m.size(), 9u);  // uint32 length + "hello"
    }
  }
}

TEST(Ros1BagCheck, IndexEntriesMustPointAtMessageRecordsInTheirChunk) {
  for (const std::string compression : {"none", "bz2", "lz4"}) {
    SCOPED_TRACE(compression);
    Knobs k;
    k.compression = compression;
    k.index_offset_delta = 1;  // inside the message record
    expect_refused(k, "where no message-data record starts");
    k.index_offset_delta = -(std::int64_t(1) << 20);  // wraps far outside the chunk
    expect_refused(k, "where no message-data record starts");
    k.index_offset_delta = 0x10000000;  // the CI crash: far past the chunk's buffer
    expect_refused(k, "where no message-data record starts");
  }
  Knobs at_connection;
  at_connection.index_offset_delta = -static_cast<std::int64_t>(
      record(op(0x07) + field("conn", u32(0)) + field("topic", "/chatter"), kConnectionHeader).size());
  expect_refused(at_connection, "where no message-data record starts");  // offset 0: a connection
}

TEST(Ros1BagCheck, IndexAndChunkInfoCountsMustMatchTheirData) {
  Knobs unknown;
  unknown.index_conn = 7;
  expect_refused(unknown, "indexes connection 7, which has no connection record");
  Knobs index_count;
  index_count.index_count_extra = 1000;
  expect_refused(index_count, "counts 1001 entries but holds 12 bytes");
  Knobs info_count;
  info_count.info_count_extra = 1;
  expect_refused(info_count, "counts 2 connections but holds 8 bytes");
  Knobs connections;
  connections.conn_count_extra = 5;  // more connection records than the index section holds
  expect_refused(connections, "is not a connection record");
}

TEST(Ros1BagCheck, ChunksMustDecompressToExactlyTheirDeclaredSize) {
  for (const std::string compression : {"none", "bz2", "lz4"}) {
    SCOPED_TRACE(compression);
    Knobs k;
    k.compression = compression;
    k.size_delta = 100;
    expect_refused(k, compression == "none" ? "but its header declares" : "bytes, but its header declares");
    k.size_delta = -10;
    expect_refused(k, compression == "none" ? "but its header declares" : "decompresses to more than its declared");
    k.size_delta = std::int64_t(3) << 30;  // 3 GiB as a uint32: refused before anything is sized
    expect_refused(k, "(over 1 GiB)");
  }
}

TEST(Ros1BagCheck, CorruptOrCutCompressedStreamsAreRefused) {
  for (const std::string compression : {"bz2", "lz4"}) {
    SCOPED_TRACE(compression);
    Knobs corrupt;
    corrupt.compression = compression;
    corrupt.mangle_compressed = [](std::string& s) { for (std::size_t i = 4; i < s.size(); i += 3) s[i] ^= 0x5a; };
    expect_refused(corrupt, "corrupt");
    Knobs cut;
    cut.compression = compression;
    cut.mangle_compressed = [](std::string& s) { s.resize(s.size() / 2); };
    expect_refused(cut, "the chunk at byte");
  }
  Knobs unknown;
  unknown.compression = "zstd";
  expect_refused(unknown, "unknown compression 'zstd'");
}

TEST(Ros1BagCheck, RecordsInsideAChunkMustTileIt) {
  for (const std::string compression : {"none", "lz4"}) {
    SCOPED_TRACE(compression);
    Knobs k;
    k.compression = compression;
    k.message_data_extra = 40;
    expect_refused(k, "runs past the end of the chunk");
  }
}

TEST(Ros1BagCheck, HeadersMustParseAndEncryptedBagsAreRefused) {
  Knobs encrypted;
  encrypted.encryptor = "rosbag/AesCbcEncryptor";
  expect_refused(encrypted, "encrypted bags (rosbag/AesCbcEncryptor) are not supported");
  // A header field claiming more bytes than its header holds (librosbag's parser would read on).
  std::string bag = make_bag(Knobs{});
  const std::size_t at = bag.find(field("compression", "none"));
  ASSERT_NE(at, std::string::npos);
  bag.replace(at, 4, u32(900000));
  const fs::path path = write_bag(bag, "field-past-header");
  try {
    scfloam::check_ros1_bag_records(path);
    FAIL() << "accepted a header field running past its header";
  } catch (const scfloam::Error& e) {
    EXPECT_NE(std::string(e.what()).find("runs past the end of its header"), std::string::npos) << e.what();
  }
}

TEST(Ros1BagCheck, FuzzedTwoGigabyteHeaderLengthIsRefusedBeforeLibrosbag) {
  const fs::path bag = fs::path(__FILE__).parent_path() / "fuzz_regressions" / "ros1_bag" /
                       "oom-connection-header-2gb.bag";
  try {
    scfloam::check_ros1_bag_records(bag);
    FAIL() << "accepted a record that runs past the end of the file";
  } catch (const scfloam::Error& e) {
    EXPECT_NE(std::string(e.what()).find("runs past the end"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(bag.filename().string()), std::string::npos) << e.what();
  }
}

TEST(Ros1BagCheck, RealBagsPass) {
  SCFLOAM_SHARED_DATA_OR_SKIP(bags, "bags");
  int checked = 0;
  for (const auto& entry : fs::recursive_directory_iterator(bags)) {
    if (entry.path().extension() != ".bag") continue;
    EXPECT_NO_THROW(scfloam::check_ros1_bag_records(entry.path())) << entry.path();
    ++checked;
  }
  EXPECT_GE(checked, 5);
}
