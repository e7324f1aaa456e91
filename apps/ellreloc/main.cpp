// The `ellreloc` command: simulate, observe, map, relocalize, evaluate, report, demo.
// Exit codes: 0 success, 2 bad usage or bad input (one line on stderr), 1 anything else.

#include <CLI/CLI.hpp>
#include <cstdio>

#include "commands.hpp"
#include "ellreloc/error.hpp"

using namespace ellreloc::cli;

int main(int argc, char** argv) {
  CLI::App app("ellreloc: object-based camera relocalization with ellipses and ellipsoids", "ellreloc");
  app.require_subcommand(1);
  Console console;
  app.add_flag("-q,--quiet", console.quiet, "print nothing but results and errors (before or after the subcommand)");
  app.fallthrough();  // subcommands, added below, pass -q on to the app whichever side of them it is
  app.footer("Run `ellreloc SUBCOMMAND --help` for a subcommand's options and an example.");
  app.set_version_flag("--version", "ellreloc " ELLRELOC_VERSION, "print the version and exit");

  SimulateArgs sim;
  ObserveArgs obs;
  MapArgs mp;
  RelocalizeArgs rl;
  EvaluateArgs ev;
  ReportArgs rp;
  DemoArgs dm;
  CLI::App* s = addSimulateCommand(app, sim);
  CLI::App* o = addObserveCommand(app, obs);
  CLI::App* m = addMapCommand(app, mp);
  CLI::App* r = addRelocalizeCommand(app, rl);
  CLI::App* e = addEvaluateCommand(app, ev);
  CLI::App* p = addReportCommand(app, rp);
  CLI::App* d = addDemoCommand(app, dm);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& h) {
    return app.exit(h);
  } catch (const CLI::CallForAllHelp& h) {
    return app.exit(h);
  } catch (const CLI::CallForVersion& v) {
    return app.exit(v);
  } catch (const CLI::ParseError& err) {
    if (argc > 1 && argv[1][0] != '-' && app.get_subcommands().empty())
      std::fprintf(stderr, "ellreloc: unknown subcommand '%s' (see --help)\n", argv[1]);
    else
      std::fprintf(stderr, "ellreloc: %s (see --help)\n", err.what());
    return 2;
  }
  try {
    if (s->parsed()) simulate(sim, console);
    if (o->parsed()) observe(obs, console);
    if (m->parsed()) map(mp, console);
    rl.use_points = r->get_option("--points")->count() > 0;
    if (r->parsed()) relocalize(rl, console);
    if (e->parsed()) printEvaluation(evaluate(ev));
    if (p->parsed()) report(rp, console);
    if (d->parsed()) demo(dm, console);
  } catch (const ellreloc::Error& err) {
    std::fprintf(stderr, "ellreloc: %s\n", err.what());
    return 2;
  } catch (const std::exception& err) {
    std::fprintf(stderr, "ellreloc: internal error: %s\n", err.what());
    return 1;
  }
  return 0;
}
