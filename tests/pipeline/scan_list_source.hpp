// An in-memory ScanSource for tests that feed the pipeline hand-made (or broken) scans.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "scfloam/io/scan_source.hpp"

namespace scfloam::test {

class ScanListSource final : public ScanSource {
 public:
  explicit ScanListSource(std::vector<Scan> scans) : scans_(std::move(scans)) {}
  std::size_t size() const override { return scans_.size(); }
  Scan load(std::size_t index) const override { return scans_.at(index); }
  std::string describe() const override {
    return "test scans (" + std::to_string(scans_.size()) + ")";
  }

 private:
  std::vector<Scan> scans_;
};

}  // namespace scfloam::test
