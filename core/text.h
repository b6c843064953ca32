#pragma once

// Checks of text that ends up in JSON and in messages: UTF-8 (RFC 3629).

#include <cstddef>
#include <optional>
#include <string_view>

namespace costar {

/// The length of the UTF-8 character `text` starts with, or 0 when its first bytes are not one
/// (RFC 3629: no overlong forms, no UTF-16 surrogates, nothing above U+10FFFF).
std::size_t utf8Length(std::string_view text);

/// The index of the first byte of `text` that does not start a UTF-8 character (utf8Length());
/// nullopt when all of it is UTF-8.
std::optional<std::size_t> invalidUtf8At(std::string_view text);

}  // namespace costar
