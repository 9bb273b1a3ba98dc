// clumpkit: multi-sphere clumps for DEM. Commands register themselves (cmd_*.cpp); this file only
// dispatches and turns user-input errors into one line on stderr and exit status 2.
#include <algorithm>
#include <iostream>

#include "cli_util.hpp"
#include "clumpkit/core/error.hpp"

int main(int argc, char** argv) {
  using namespace clumpkit;
  CLI::App app{"clumpkit " CLUMPKIT_VERSION
               ": multi-sphere (clump) particles for DEM: fill shapes, measure shape error,\n"
               "export templates, run the validation rigs, compare with measurements."};
  app.require_subcommand(1);
  app.set_version_flag("--version", CLUMPKIT_VERSION);
  auto& reg = cli::registry();
  std::stable_sort(reg.begin(), reg.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<cli::Command> commands;
  for (const auto& [order, setup] : reg) commands.push_back(setup(app));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // One line, like every other input error (CLI11's own report takes two).
    std::cerr << "clumpkit: error: " << InputError(e.what()).what()
              << " (run with --help for usage)\n";
    return 2;
  }
  try {
    for (const auto& c : commands)
      if (c.app->parsed()) return c.run();
  } catch (const InputError& e) {
    std::cerr << "clumpkit: error: " << e.what() << "\n";
    return 2;
  } catch (const NumericalError& e) {
    std::cerr << "clumpkit: simulation stopped: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "clumpkit: internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
