// The trajectory files scfloam eval reads (KITTI, TUM, times), detection and pairing.
#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

SCFLOAM_FUZZ_TARGET("trajectory", ".txt")
