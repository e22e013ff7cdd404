// Facade detail on building walls without extra primitives: a procedural pattern per
// building (storey height, window bays, shop fronts, floor ledges, curtain walls) refines a
// ray's hit on a wall: recessed windows and doors (the ray may end on the reveal), ledges
// standing out, and glass that returns weakly, not at all, or lets the ray into the room.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "scfloam/sim/world.hpp"

namespace scfloam::sim {


// `hit` is the ray's hit on a vertical wall of building box `p` (index `index` in the
// world); updates range, normal and reflectance. Returns false when the ray gives no return.
bool refine_facade_hit(const Primitive& p, std::uint32_t index, const Eigen::Vector3d& origin,
                       const Eigen::Vector3d& dir, std::uint64_t ray_seed, const FacadeConfig& config,
                       RayHit* hit);

}  // namespace scfloam::sim
