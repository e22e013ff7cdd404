// read_kitti_calib on arbitrary text: the Tr line, numbers, the rigid-transform check.
#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

SCFLOAM_FUZZ_TARGET("kitti_calib", ".txt")
