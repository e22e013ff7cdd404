// load_config on arbitrary YAML: unknown keys, wrong types, malformed documents.
#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

SCFLOAM_FUZZ_TARGET("config", ".yaml")
