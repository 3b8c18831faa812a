# navimpact diagnose-power on a tiny sweep: exit code 0, power.md and
# power.json written, the run counts recorded, every run judged.
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${NI} diagnose-power --out ${OUT} --runs 2 --null-runs 1 --snr 5:5
                        --samples 8192:16384 --causes sinusoid,level_shift,outliers --threads 2
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "diagnose-power failed (${rc}):\nstdout: ${out}\nstderr: ${err}")
endif()
foreach(f power.md power.json)
  if(NOT EXISTS ${OUT}/${f})
    message(FATAL_ERROR "missing output ${f}")
  endif()
endforeach()
file(READ ${OUT}/power.json j)
string(JSON nr GET "${j}" null runs)
string(JSON n LENGTH "${j}" runs)
if(NOT nr EQUAL 1 OR NOT n EQUAL 6)
  message(FATAL_ERROR "power.json: expected 1 null run and 6 effect runs, got ${nr} and ${n}")
endif()
string(JSON seed GET "${j}" seed)
if(NOT seed MATCHES "^[0-9]+$")
  message(FATAL_ERROR "power.json: no seed recorded")
endif()
