// `scfloam info INPUT`: what an input holds (kind, topics, scans, fields, time span) before
// anything runs; a file it cannot read gives the reason and exit code 1.
#include <cstdio>

#include "command_registry.hpp"
#include "scfloam/io/input_inspect.hpp"

namespace scfloam::cli {
namespace {

struct InfoArgs {
  std::string input;
  std::string topic;
  std::string timestamps;
  bool json = false;
};

RegisterCommand reg("info", [](CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  auto* sub = app.add_subcommand("info", "Describe an input (KITTI directory, scan folder or file, ROS bag) without running");
  sub->add_option("input", args->input, "Input: KITTI directory, folder of .pcd/.ply/.bin, scan file, or ROS bag")->required();
  sub->add_option("--topic", args->topic, "Bags: the PointCloud2 topic to describe (auto when only one)");
  sub->add_option("--timestamps", args->timestamps, "Folders: a file with one stamp per scan");
  sub->add_flag("--json", args->json, "Print one JSON object instead of text");
  sub->callback([args] {
    ScanSourceOptions options;
    options.topic = args->topic;
    options.timestamps_file = args->timestamps;
    const InputInfo info = inspect_input(args->input, options);
    const std::string text = args->json ? input_info_json(info) : input_info_text(info);
    std::fputs(text.c_str(), stdout);
  });
});

}  // namespace
}  // namespace scfloam::cli
