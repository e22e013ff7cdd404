// An MCAP file (our own reader: records, chunks, zstd/lz4, summary indexes) as a bag.
#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

SCFLOAM_FUZZ_TARGET("mcap", ".mcap")
