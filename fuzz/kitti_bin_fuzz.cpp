// read_kitti_bin on arbitrary bytes: size checks, non-finite values.
#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

SCFLOAM_FUZZ_TARGET("kitti_bin", ".bin")
