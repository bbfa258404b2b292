// What a crowd cache entry must hold to be used: its name promises a
// database built with animation from the manifest's clips (the digest in
// the name covers their bytes), so a valid .mmdb placed there that lacks the
// animation, or holds other motion, is a bad entry. Bad entries are rebuilt
// with a note naming them (default_data.cpp), never fatal.
#pragma once

#include "mmvk/database/database.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::crowd {

// Errors say what the entry lacks or holds instead ("no animation", "clip 3
// is 'run' from run.bvh, the manifest's is 'walk' from walk.bvh").
Status validate_cache_entry(const Database& database, const Manifest& manifest);

}  // namespace mmvk::crowd
