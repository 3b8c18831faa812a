# navimpact sweep / sweep-merge: a small sweep writes its map; shards merged
# give the same files byte for byte; a merge names the missing shards and
# refuses a shard of another seed; bad config keys are named; nothing is left
# behind by a failing command.
set(_swdir ${CMAKE_CURRENT_BINARY_DIR}/sweep)
set(_swcfg ${CMAKE_SOURCE_DIR}/tests/data/sweep_small.yaml)
add_test(NAME cli_sweep_small_shards_and_merge
         COMMAND ${CMAKE_COMMAND} -DNI=${NI} -DCONFIG=${_swcfg} -DD=${_swdir}
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/sweep_check.cmake)

function(_sweep_bad name args regex)
  add_test(NAME cli_sweep_bad_${name}
           COMMAND ${CMAKE_COMMAND} -DNI=${NI} "-DARGS=${args}" "-DREGEX=${regex}"
                   -DOUTDIR=${_swdir}/bad_${name} -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_fail.cmake)
endfunction()
_sweep_bad(no_sweep_block "sweep|--config|${CMAKE_SOURCE_DIR}/config/paper/study_navchip_uav.yaml|--out|${_swdir}/bad_no_sweep_block"
           "outages.: not used by a sweep")
_sweep_bad(one_run "sweep|--config|${_swcfg}|--out|${_swdir}/bad_one_run|--runs|1" "--runs must be >= 2")
_sweep_bad(merge_nothing "sweep-merge|${_swdir}/no_such_shard|--out|${_swdir}/bad_merge_nothing"
           "1 of 1 folders hold no shard.*no_such_shard")
