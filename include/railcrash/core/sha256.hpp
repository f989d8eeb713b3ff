// SHA-256 (FIPS 180-4) of a text: the model files' digests in a run's provenance
// (results/provenance.hpp), the same digest `sha256sum` prints.
#pragma once

#include <string>
#include <string_view>

namespace railcrash {

/// The SHA-256 digest of `bytes` as 64 lower-case hexadecimal digits.
std::string sha256_hex(std::string_view bytes);

}  // namespace railcrash
