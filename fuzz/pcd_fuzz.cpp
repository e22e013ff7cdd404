// read_pcd on arbitrary bytes: ascii, binary and LZF-compressed PCD headers and data.
#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

SCFLOAM_FUZZ_TARGET("pcd", ".pcd")
