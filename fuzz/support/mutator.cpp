#include "fuzz/support/mutator.h"

#include <array>

namespace meshnav::fuzz {

namespace {

/// Tokens that break parsers: edges of int32/int64/double, non-numbers, separators, YAML syntax.
const std::array<const char*, 34> kTokens = {
    "0", "-1", "1e308", "-1e308", "1e-320", "nan", "-nan", "inf", "-inf", ".inf", ".nan",
    "2147483647", "2147483648", "-2147483649", "4294967297", "9223372036854775807",
    "-9223372036854775808", "18446744073709551616", "0x7fffffff", ",", ",,", "\n", "\r\n", "#",
    " ", "\t", "\"", ":", "- ", "[", "]", "{", "~", "&a *a"};

}  // namespace

size_t Mutator::below(size_t n) { return n == 0 ? 0 : static_cast<size_t>(rng_() % n); }

void Mutator::editOnce(std::string& s, const std::string& other) {
  const size_t pos = below(s.size() + 1);
  switch (below(8)) {
    case 0:  // flip one bit
      if (!s.empty()) s[below(s.size())] ^= static_cast<char>(1u << below(8));
      break;
    case 1:  // overwrite one byte with any value
      if (!s.empty()) s[below(s.size())] = static_cast<char>(below(256));
      break;
    case 2:  // insert a few random bytes
      s.insert(pos, std::string(1 + below(4), static_cast<char>(below(256))));
      break;
    case 3:  // erase a piece
      if (!s.empty()) s.erase(below(s.size()), 1 + below(16));
      break;
    case 4:  // insert a token at the edge of a type or of the syntax
      s.insert(pos, kTokens[below(kTokens.size())]);
      break;
    case 5:  // repeat a piece
      if (!s.empty()) {
        const size_t from = below(s.size());
        const std::string piece = s.substr(from, 1 + below(64));
        s.insert(pos, piece);
      }
      break;
    case 6:  // cut the end off
      s.resize(below(s.size() + 1));
      break;
    default:  // splice a piece of another corpus file
      if (!other.empty()) {
        const size_t from = below(other.size());
        s.insert(pos, other.substr(from, 1 + below(128)));
      }
      break;
  }
}

std::string Mutator::mutate(const std::string& input, const std::string& other) {
  std::string s = input;
  const size_t edits = 1 + below(4);
  for (size_t i = 0; i < edits; ++i) editOnce(s, other);
  return s;
}

}  // namespace meshnav::fuzz
