#include "scfloam/loop/path_gate.hpp"

#include <algorithm>
#include <functional>
#include <limits>
#include <queue>
#include <string>

#include "scfloam/error.hpp"

namespace scfloam {

void GraphPathLengths::add_keyframe(double step_m) {
  along_m_.push_back(along_m_.empty() ? 0.0 : along_m_.back() + std::max(step_m, 0.0));
}

void GraphPathLengths::add_loop(std::size_t a, std::size_t b) {
  if (a >= size() || b >= size())
    throw Error("graph path lengths: loop " + std::to_string(a) + "-" + std::to_string(b) +
                " outside " + std::to_string(size()) + " keyframes");
  loops_.emplace_back(a, b);
}

std::vector<double> GraphPathLengths::from(std::size_t source,
                                           const std::vector<std::size_t>& targets) const {
  // Only the source, the targets and the loops' ends matter: between two of them, adjacent in
  // keyframe order, the chain is the only link. Dijkstra on that small graph.
  std::vector<std::size_t> nodes{source};
  nodes.insert(nodes.end(), targets.begin(), targets.end());
  for (const auto& [a, b] : loops_) nodes.insert(nodes.end(), {a, b});
  for (std::size_t n : nodes)
    if (n >= size()) throw Error("graph path lengths: keyframe " + std::to_string(n) + " unknown");
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  const auto slot = [&](std::size_t kf) {
    return static_cast<std::size_t>(std::lower_bound(nodes.begin(), nodes.end(), kf) - nodes.begin());
  };
  std::vector<std::vector<std::pair<std::size_t, double>>> links(nodes.size());
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    const double w = along_m_[nodes[i]] - along_m_[nodes[i - 1]];
    links[i - 1].emplace_back(i, w);
    links[i].emplace_back(i - 1, w);
  }
  for (const auto& [a, b] : loops_) {
    links[slot(a)].emplace_back(slot(b), 0.0);
    links[slot(b)].emplace_back(slot(a), 0.0);
  }
  std::vector<double> dist(nodes.size(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  dist[slot(source)] = 0.0;
  open.emplace(0.0, slot(source));
  while (!open.empty()) {
    const auto [d, i] = open.top();
    open.pop();
    if (d > dist[i]) continue;
    for (const auto& [j, w] : links[i])
      if (d + w < dist[j]) open.emplace(dist[j] = d + w, j);
  }
  std::vector<double> out;
  out.reserve(targets.size());
  for (std::size_t t : targets) out.push_back(dist[slot(t)]);
  return out;
}

}  // namespace scfloam
