// Value checks for the subcommands' numeric options, done by the parser, with one-line errors
// that say what is meant (CLI11's PositiveNumber prints its range up to DBL_MAX in full).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace auvdock::cli {

// A finite number > 0 (Positive) or >= 0 (NonNegative); the error names the unit, e.g.
// "--pixel-sigma: must be a positive number of pixels (got '-1')".
CLI::Validator Positive(const std::string& unit);
CLI::Validator NonNegative(const std::string& unit);

}  // namespace auvdock::cli
