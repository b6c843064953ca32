#pragma once
// The token that every request changing anything or moving the robot must carry
// (`Authorization: Bearer <token>`).

#include <filesystem>
#include <string>
#include <string_view>

namespace costar::server {

/// 32 random bytes from the system's CSPRNG, as 64 hex digits.
std::string randomToken();

/// The token kept in `file`: read it when the file exists (it must be a regular file that
/// only its owner may read or write, mode 0600 or stricter, holding at least 16 characters),
/// else create it with mode 0600 and a new random token.
/// @throws std::runtime_error saying what is wrong (permissions, too short, cannot write).
std::string tokenFromFile(const std::filesystem::path& file);

/// Compares in time that does not depend on where the strings differ.
bool sameToken(std::string_view given, std::string_view expected);

/// The token of an `Authorization: Bearer <token>` header value; empty if it is not one.
std::string_view bearerToken(std::string_view authorization);

}  // namespace costar::server
