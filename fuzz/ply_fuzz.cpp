// read_ply on arbitrary bytes: ascii and binary PLY headers and data.
#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

SCFLOAM_FUZZ_TARGET("ply", ".ply")
