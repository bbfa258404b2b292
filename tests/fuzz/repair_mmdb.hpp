// Makes fuzzed bytes pass the .mmdb loader's first gates (magic, version,
// payload size, checksum; database_io.hpp) so that mutations reach the
// payload parser and Database::create instead of dying at the checksum.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

#include "mmvk/common/hash.hpp"
#include "mmvk/database/database_io.hpp"

namespace mmvk::fuzz {

inline void repair_mmdb(std::string& bytes) {
  constexpr std::size_t kChecksumBytes = 8;
  if (bytes.size() < kDatabaseHeaderBytes + kChecksumBytes) return;
  std::memcpy(bytes.data(), "MMVKDB\n\0", 8);
  // Keep a version the loader knows (the fuzzer may flip it back to others
  // through the corpus; the plain target covers those): the seed's own when
  // known, since versions 2 and 3 lay the payload out differently.
  std::uint32_t version = 0;
  std::memcpy(&version, bytes.data() + 8, 4);
  if (version < 1 || version > kDatabaseFormatVersion) version = kDatabaseFormatVersion;
  std::memcpy(bytes.data() + 8, &version, 4);
  const std::uint64_t payload = bytes.size() - kDatabaseHeaderBytes - kChecksumBytes;
  std::memcpy(bytes.data() + 16, &payload, 8);
  Hasher hasher;
  hasher.add_bytes(bytes.data(), bytes.size() - kChecksumBytes);
  const std::uint64_t digest = hasher.digest();
  std::memcpy(bytes.data() + bytes.size() - kChecksumBytes, &digest, 8);
}

}  // namespace mmvk::fuzz
