// qem: the command-line tool. Each subcommand lives in its own cmd_*.cpp and registers itself.
#include <algorithm>
#include <cstdio>
#include <vector>

#include "command.h"
#include "huge_pages.h"
#include "qem/error.h"

namespace qem::cli {

namespace {
struct Entry {
  int order;
  CommandFactory factory;
};
std::vector<Entry>& registry() {
  static std::vector<Entry> entries;
  return entries;
}
}  // namespace

bool register_command(int order, CommandFactory factory) {
  registry().push_back({order, std::move(factory)});
  return true;
}

}  // namespace qem::cli

int main(int argc, char** argv) {
  using namespace qem::cli;
  with_malloc_tunables(argv);
  CLI::App app{"qem: triangle mesh simplification with quadric error metrics (Garland & Heckbert 1997)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "qem 0.1.0");
  auto entries = registry();
  std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.order < b.order; });
  std::vector<std::pair<CLI::App*, std::function<int()>>> runners;
  for (auto& e : entries) {
    std::size_t before = app.get_subcommands({}).size();
    auto run = e.factory(app);
    auto subs = app.get_subcommands({});
    if (subs.size() > before) runners.emplace_back(subs.back(), std::move(run));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    for (auto& [sub, run] : runners)
      if (sub->parsed()) return run();
  } catch (const qem::Error& e) {
    std::fprintf(stderr, "qem: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "qem: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "qem: internal error: %s\n", e.what());
    return 3;
  }
  return 2;
}
