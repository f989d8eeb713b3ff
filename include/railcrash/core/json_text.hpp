// JSON string literals for any text (summary.json, model.json, the schema, provenance): the
// core layer's, so that every layer writing JSON can use them.
#pragma once

#include <string>

namespace railcrash {

/// Text with every byte sequence that is not well-formed UTF-8 (RFC 3629: no overlong forms,
/// no surrogates, nothing above U+10FFFF, no truncated sequence) replaced by U+FFFD.
std::string valid_utf8(const std::string& text);
/// A JSON string literal (RFC 8259) for any text: quotes, backslashes and control bytes escaped,
/// and invalid UTF-8 (a model path in Latin-1, say) replaced through valid_utf8, so the
/// document stays parseable whatever the user's file names hold.
std::string json_string(const std::string& text);
}  // namespace railcrash
