# libFuzzer targets for the host tools' readers (issue 19): the log reader,
# the dataset manifest and the model file. Included by fuzz/CMakeLists.txt
# after it found a clang that links -fsanitize=fuzzer (fuzz_sanitize).
# Host code: exceptions and RTTI on (the readers report errors by
# exception); compiled by custom commands calling clang++ directly, like
# link_fuzzer. Each runs 10 s in the suite from its seed corpus, and by hand
# for as long as wanted (docs/fuzzing.md).

get_target_property(hadynet_fuzz_eigen_inc Eigen3::Eigen INTERFACE_INCLUDE_DIRECTORIES)
get_target_property(hadynet_fuzz_json_inc nlohmann_json::nlohmann_json INTERFACE_INCLUDE_DIRECTORIES)
set(host_fuzz_flags -std=c++20 -O2 -g -fno-omit-frame-pointer ${fuzz_sanitize}
    -I${PROJECT_SOURCE_DIR} -I${hadynet_fuzz_eigen_inc} -I${hadynet_fuzz_json_inc}
    -Wall -Wextra -Wno-unknown-pragmas)

# hadynet_host_fuzzer(NAME SOURCES...): builds fuzz/NAME from the sources
# (relative to the repository) and registers NAME_smoke: 10 s from
# fuzz/corpus/<CORPUS>.
function(hadynet_host_fuzzer name corpus max_len)
  set(objects "")
  set(index 0)
  foreach(rel IN LISTS ARGN)
    set(src "${PROJECT_SOURCE_DIR}/${rel}")
    get_filename_component(stem "${src}" NAME_WE)
    set(obj "${CMAKE_CURRENT_BINARY_DIR}/${name}_objs/${index}_${stem}.o")
    math(EXPR index "${index} + 1")
    add_custom_command(
      OUTPUT "${obj}"
      COMMAND "${CMAKE_COMMAND}" -E make_directory "${CMAKE_CURRENT_BINARY_DIR}/${name}_objs"
      COMMAND "${HADYNET_FUZZ_CLANGXX}" ${host_fuzz_flags} -MD -MF "${obj}.d" -c "${src}" -o "${obj}"
      DEPENDS "${src}"
      DEPFILE "${obj}.d"
      COMMENT "Compiling ${rel} for ${name} (clang, libFuzzer + ASan + UBSan)"
      VERBATIM)
    list(APPEND objects "${obj}")
  endforeach()
  set(fuzzer "${CMAKE_CURRENT_BINARY_DIR}/${name}")
  add_custom_command(
    OUTPUT "${fuzzer}"
    COMMAND "${HADYNET_FUZZ_CLANGXX}" ${fuzz_sanitize} ${objects} -o "${fuzzer}"
    DEPENDS ${objects}
    COMMENT "Linking ${name}"
    VERBATIM)
  add_custom_target(hadynet_${name} ALL DEPENDS "${fuzzer}")
  add_test(NAME ${name}_smoke
    COMMAND "${CMAKE_COMMAND}" "-DFUZZER=${fuzzer}" "-DCORPUS=${CMAKE_CURRENT_SOURCE_DIR}/corpus/${corpus}"
            "-DWORK=${CMAKE_CURRENT_BINARY_DIR}/${name}_run" -DSECONDS=10 -DMAX_LEN=${max_len}
            -P "${CMAKE_CURRENT_SOURCE_DIR}/run_link_fuzzer.cmake")
  set_tests_properties(${name}_smoke PROPERTIES TIMEOUT 60 LABELS fuzz)
endfunction()

set(hadynet_fuzz_datalog datalog/dataset_manifest.cc datalog/log_error.cc datalog/log_reader.cc
    datalog/log_rules.cc datalog/log_table.cc datalog/log_writer.cc)
hadynet_host_fuzzer(log_fuzzer log 4096 fuzz/log_fuzzer.cc ${hadynet_fuzz_datalog})
hadynet_host_fuzzer(manifest_fuzzer manifest 4096 fuzz/manifest_fuzzer.cc ${hadynet_fuzz_datalog})
hadynet_host_fuzzer(model_fuzzer model 16384 fuzz/model_fuzzer.cc ${hadynet_fuzz_datalog}
    trainer/model_file.cc trainer/safetensors.cc trainer/hadynet_params.cc trainer/log_dataset.cc
    trainer/sensor_model.cc trainer/derived_inputs.cc)
