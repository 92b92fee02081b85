// Usage errors that name what was mistyped and the closest valid word: an unknown subcommand
// ("auvdock rnu": did you mean 'run'?) or an unknown long option of the chosen subcommand
// ("run --datset": did you mean '--dataset'?). Checked before CLI11 parses, so that the message
// is about the typo and not about what it left missing ("--dataset is required").
//
// Closest: the smallest edit distance (insertions, deletions, substitutions and swaps of two
// neighbouring characters: the optimal-string-alignment distance), suggested
// when it is at most max(2, length / 3) of the typed word; otherwise the valid words are listed
// (subcommands) or --help is pointed to (options).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace auvdock::cli {

// Edit distance between a and b (as above).
int EditDistance(const std::string& a, const std::string& b);

// args: argv[1..]. Empty when every subcommand and long option is known (or args hold none);
// otherwise the one-line message. Words after a bare "--" are not options.
std::string UnknownWordMessage(CLI::App& app, const std::vector<std::string>& args);

}  // namespace auvdock::cli
