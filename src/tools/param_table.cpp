// Prints the parameter tables: `param_table --markdown` is docs/parameters.md,
// `param_table --cfg` is cfg/Planes.cfg, `--tracker-cfg` cfg/Tracker.cfg (dynamic_reconfigure).
#include <iostream>

#include "cli_args.h"
#include "mono_plane_detection/params/param_table.h"

namespace cli = mono_plane_detection::cli;

int main(int argc, char** argv) {
  bool markdown = false, cfg = false, tracker_cfg = false;
  cli::Parser cli("param_table", "--markdown | --cfg | --tracker-cfg",
                  "  Prints the parameter tables of both nodelets, the one declaration of every\n"
                  "  parameter (name, default, range, unit, meaning).",
                  "exit codes: 0 printed, 2 bad usage\n");
  cli.flag("markdown", &markdown,
           "docs/parameters.md (param_table --markdown > docs/parameters.md)")
      .flag("cfg", &cfg,
            "cfg/Planes.cfg, the plane nodelet's dynamic_reconfigure parameters (then chmod +x "
            "it)")
      .flag("tracker-cfg", &tracker_cfg,
            "cfg/Tracker.cfg, the tracker nodelet's dynamic_reconfigure parameters (then chmod "
            "+x it)");
  if (const auto code = cli.parse(argc, argv)) return *code;
  if (markdown + cfg + tracker_cfg != 1)
    return cli.fail("give one of --markdown, --cfg and --tracker-cfg");
  std::cout << (markdown ? mono_plane_detection::parametersMarkdown()
                : cfg    ? mono_plane_detection::dynamicReconfigureCfg()
                         : mono_plane_detection::trackerReconfigureCfg());
  return 0;
}
