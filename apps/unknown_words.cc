#include "apps/unknown_words.h"

#include <algorithm>

namespace auvdock::cli {
namespace {

// The closest of candidates to word, or empty when none is close enough to be a typo of it.
std::string Closest(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  int best_distance = 0;
  for (const std::string& c : candidates) {
    const int d = EditDistance(word, c);
    if (best.empty() || d < best_distance) {
      best = c;
      best_distance = d;
    }
  }
  const int allowed = std::max(2, static_cast<int>(word.size()) / 3);
  return best_distance <= allowed ? best : std::string();
}

std::string Join(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

}  // namespace

int EditDistance(const std::string& a, const std::string& b) {
  // d[i][j]: distance between the first i characters of a and the first j of b.
  std::vector<std::vector<int>> d(a.size() + 1, std::vector<int>(b.size() + 1, 0));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = static_cast<int>(i);
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      const int substitution = d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, substitution});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);  // two neighbours swapped
      }
    }
  }
  return d[a.size()][b.size()];
}

std::string UnknownWordMessage(CLI::App& app, const std::vector<std::string>& args) {
  if (args.empty() || args[0].empty() || args[0][0] == '-') return {};
  std::vector<std::string> names;
  CLI::App* sub = nullptr;
  for (CLI::App* s : app.get_subcommands([](CLI::App*) { return true; })) {
    names.push_back(s->get_name());
    if (s->get_name() == args[0]) sub = s;
  }
  if (!sub) {
    const std::string closest = Closest(args[0], names);
    return "unknown subcommand '" + args[0] + "'" +
           (closest.empty() ? "" : " (did you mean '" + closest + "'?)") +
           "; the subcommands: " + Join(names);
  }
  std::vector<std::string> options = {"help"};
  for (const CLI::Option* option : sub->get_options()) {
    for (const std::string& name : option->get_lnames()) options.push_back(name);
  }
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--") break;
    if (arg.size() < 3 || arg.compare(0, 2, "--") != 0) continue;
    const std::string name = arg.substr(2, arg.find('=') - 2);
    if (std::find(options.begin(), options.end(), name) != options.end()) continue;
    const std::string closest = Closest(name, options);
    return "unknown option '--" + name + "' of '" + sub->get_name() + "'" +
           (closest.empty() ? " (see " + sub->get_name() + " --help)"
                            : " (did you mean '--" + closest + "'?)");
  }
  return {};
}

}  // namespace auvdock::cli
