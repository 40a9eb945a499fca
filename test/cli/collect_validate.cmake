# Script test: hadynet collect --preset smoke, hadynet validate (must pass),
# then corrupt one value and validate again (must fail naming file:line:col).
file(REMOVE_RECURSE "${WORK}")
execute_process(COMMAND "${HADYNET}" collect --preset smoke --quiet --out "${WORK}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "collect failed: ${rc}")
endif()
execute_process(COMMAND "${HADYNET}" validate "${WORK}" RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "all 4 logs valid")
  message(FATAL_ERROR "validate of a fresh dataset failed (${rc}): ${out}")
endif()

set(log "${WORK}/train/Cylinder_random1_i0_w0.csv")
file(STRINGS "${log}" lines)
list(GET lines 15 row)                       # line 16 of the file: a data row
string(REGEX REPLACE "^([^,]*,[^,]*,[^,]*),[^,]*" "\\1,nan" bad_row "${row}")  # column 4 := nan
list(REMOVE_AT lines 15)
list(INSERT lines 15 "${bad_row}")
list(JOIN lines "\n" text)
file(WRITE "${log}" "${text}\n")
execute_process(COMMAND "${HADYNET}" validate "${WORK}" RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "validate accepted a log with nan")
endif()
if(NOT err MATCHES "Cylinder_random1_i0_w0.csv:16:4")
  message(FATAL_ERROR "error does not name file:line:column: ${err}")
endif()
message(STATUS "rejected as expected: ${err}")
