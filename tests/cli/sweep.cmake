# navimpact sweep / sweep-merge: a small sweep writes its map; shards merged
# give the same files byte for byte; a merge names the missing shards and
# refuses a shard of another seed; bad config keys are named; nothing is left
# behind by a failing command.
set(_swdir ${CMAKE_CURRENT_BINARY_DIR}/sweep)
set(_swcfg ${CMAKE_SOURCE_DIR}/tests/data/sweep_small.yaml)
navimpact_cli_check(cli_sweep_small_shards_and_merge CHECK sweep_shards DEFINES CONFIG=${_swcfg} D=${_swdir}/run)
navimpact_cli_fail(cli_sweep_bad_no_sweep_block
  ARGS sweep --config ${CMAKE_SOURCE_DIR}/config/paper/study_navchip_uav.yaml --out ${_swdir}/bad_no_sweep_block
  REGEX "outages.: not used by a sweep" NOOUT ${_swdir}/bad_no_sweep_block)
navimpact_cli_fail(cli_sweep_bad_one_run ARGS sweep --config ${_swcfg} --out ${_swdir}/bad_one_run --runs 1
  REGEX "--runs: Value 1 not in range 2 to 1000000" NOOUT ${_swdir}/bad_one_run)
navimpact_cli_fail(cli_sweep_bad_merge_nothing ARGS sweep-merge ${_swdir}/no_such_shard --out ${_swdir}/bad_merge
  REGEX "1 of 1 folders hold no shard.*no_such_shard" NOOUT ${_swdir}/bad_merge)
navimpact_cli_fail(cli_sweep_bad_emit_and_out
  ARGS sweep --config ${_swcfg} --out ${_swdir}/bad_emit --emit-slurm ${_swdir}/bad_emit_slurm --shards 2
  REGEX "either --out .* or --emit-slurm" NOOUT ${_swdir}/bad_emit_slurm)
navimpact_cli_fail(cli_sweep_bad_too_many_shards
  ARGS sweep --config ${_swcfg} --emit-slurm ${_swdir}/bad_shards --shards 9
  REGEX "--shards 9 is more than the 8 runs" NOOUT ${_swdir}/bad_shards)
navimpact_cli_fail(cli_sweep_bad_outage_past_end
  ARGS sweep --config ${CMAKE_SOURCE_DIR}/tests/data/bad/sweep_outage_past_end.yaml --out ${_swdir}/bad_past_end
  REGEX "sweep_outage_past_end.yaml: [^\n]*key 'sweep.outage.durations_s.2.': the outage of 40 s from 30 s ends at 70 s, after the end of the trajectory"
  NOOUT ${_swdir}/bad_past_end)
