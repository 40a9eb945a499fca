# End to end (issue 5): a held-out plant log replayed through the firmware
# image in QEMU (the MCU build with its DSP kernels, behind the real link)
# and through host-sim's q15 core must give bit-identical results: every
# column of the two CSVs but the stabiliser's losses, which only host-sim
# reports (tolerance zero: q15 is bit-identical on host and MCU).
# With -DSLOT=<file> the file is placed in model slot A of the emulated
# STM32F405 flash (0x08080000) and the firmware runs the model from there
# (docs/model-update.md): still bit-identical to host-sim's compiled-in one.
# With -DADAPT=1 the replay runs in detect mode with PB adaptation on (every
# 8th window, 2 per period, so that steps come within a short log) and every
# column, the adapted PB and its recognition included, must be identical.
# Usage: cmake -DHADYNET=<hadynet> -DIMAGE=<elf> -DMACHINE=<qemu machine> -DWORK=<dir> [-DSLOT=<file>] [-DADAPT=1] -P replay_qemu.cmake
foreach(var HADYNET IMAGE MACHINE WORK)
  if(NOT ${var})
    message(FATAL_ERROR "replay_qemu: set ${var}")
  endif()
endforeach()
if(NOT EXISTS "${IMAGE}")
  message(FATAL_ERROR "replay_qemu: no image ${IMAGE}: build the cortex-m4 preset first (scripts/test.sh does)")
endif()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "replay_qemu: failed (${rc}): ${ARGN}\n${out}${err}")
  endif()
  message(STATUS "${out}")
endfunction()

# A grasp of a state the model never trained on; control from row 20.
set(rows 60)
set(mode --control-from 20)
if(ADAPT)
  set(rows 140)
  set(mode --adapt --adapt-stride 8 --adapt-budget 2)
endif()
run("${HADYNET}" collect --object Cylinder --motion random2 --init 3 --rows ${rows} --split test --out "${WORK}" --quiet)
set(log "${WORK}/test/Cylinder_random2_i3_w0.csv")
run("${HADYNET}" replay "${log}" --out "${WORK}/host.csv" ${mode})
set(load "")
if(SLOT)
  set(load --qemu-load "${SLOT}@0x08080000")
endif()
run("${HADYNET}" replay "${log}" --out "${WORK}/qemu.csv" ${mode} --target qemu --image "${IMAGE}"
    --machine "${MACHINE}" --qemu-log "${WORK}/qemu.log" ${load})

file(STRINGS "${WORK}/host.csv" host)
file(STRINGS "${WORK}/qemu.csv" qemu)
list(LENGTH host n_host)
list(LENGTH qemu n_qemu)
math(EXPR lines "${rows} + 1")
if(NOT n_host EQUAL lines OR NOT n_qemu EQUAL lines)
  message(FATAL_ERROR "replay_qemu: expected ${lines} lines, got ${n_host} (host) and ${n_qemu} (qemu)")
endif()
foreach(i RANGE 0 ${rows})
  list(GET host ${i} h)
  list(GET qemu ${i} q)
  if(NOT ADAPT)
    # Drop the last two columns (loss_initial, loss_final): only host-sim reports them.
    string(REGEX REPLACE ",[^,]*,[^,]*$" "" h "${h}")
    string(REGEX REPLACE ",[^,]*,[^,]*$" "" q "${q}")
  endif()
  if(NOT h STREQUAL q)
    message(FATAL_ERROR "replay_qemu: row ${i} differs\n  host-sim: ${h}\n  qemu:     ${q}")
  endif()
endforeach()
if(ADAPT)
  # The last row names a trained state: at least one adaptation step was taken.
  list(GET host ${rows} last)
  if(NOT last MATCHES ",[A-Za-z0-9_-]+/[^,]*,[^,]*,[^,]*,[^,]*$")
    message(FATAL_ERROR "replay_qemu: no adaptation step in ${rows} rows: ${last}")
  endif()
  message(STATUS "replay_qemu: ${rows} rows bit-identical with PB adaptation (adapted PB, recognition) on ${MACHINE}")
else()
  message(STATUS "replay_qemu: ${rows} rows bit-identical (prediction, d, contact, command) on ${MACHINE}")
endif()
