// `candela merge`: its options; merge.cpp merges the shards.
#include "app/commands.hpp"

namespace candela {

CLI::App* add_merge_command(CLI::App* app, MergeArgs* m) {
  auto* cmd = app->add_subcommand(
      "merge",
      "Merge .exr images of disjoint sample ranges of one render (render --sample-offset K --spp N) into one, "
      "weighted by each file's spp");
  cmd->add_option("inputs", m->inputs, "Images written by candela render (.exr with candela metadata)")->required();
  cmd->add_option("-o,--output", m->output, "Merged image (.exr)")->required();
  cmd->add_flag("-q,--quiet", m->quiet, "Only the 'wrote' line");
  return cmd;
}

}  // namespace candela
