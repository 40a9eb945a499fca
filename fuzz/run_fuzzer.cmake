# Runs a libFuzzer target for a bounded time from its seed corpus; fails on
# any finding (crash, sanitizer report, oracle abort, timeout).
#   cmake -DFUZZER=<fuzzer> -DCORPUS=<seed dir> -DWORK=<scratch dir> -DSECONDS=<n> [-DMAX_LEN=<bytes>]
#         -P run_fuzzer.cmake
foreach(var FUZZER CORPUS WORK SECONDS)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_fuzzer: set ${var}")
  endif()
endforeach()

if(NOT DEFINED MAX_LEN)
  set(MAX_LEN 2048)
endif()

file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}/corpus")
# -seed: the same mutation sequence every run (the time limit still bounds it).
execute_process(
  COMMAND "${FUZZER}" -seed=1 -max_total_time=${SECONDS} -max_len=${MAX_LEN} -timeout=10 -rss_limit_mb=2048
          -print_final_stats=1 "-artifact_prefix=${WORK}/" "${WORK}/corpus" "${CORPUS}"
  RESULT_VARIABLE result
  OUTPUT_VARIABLE out
  ERROR_VARIABLE out)
string(REGEX MATCH "stat::number_of_executed_units: *[0-9]+" runs "${out}")
message("run_fuzzer: ${FUZZER}: ${runs}")
if(NOT result EQUAL 0)
  message(FATAL_ERROR "${FUZZER} failed (${result}); artifacts in ${WORK}\n${out}")
endif()
