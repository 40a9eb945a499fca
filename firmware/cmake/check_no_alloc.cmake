# Fails if a firmware library defines or references heap or exception-runtime
# symbols. Usage:
#   cmake -DNM=<nm> -DLIBRARY=<lib.a> -P check_no_alloc.cmake
if(NOT NM OR NOT LIBRARY)
  message(FATAL_ERROR "check_no_alloc: set NM and LIBRARY")
endif()

execute_process(COMMAND "${NM}" -C "${LIBRARY}"
                OUTPUT_VARIABLE symbols
                RESULT_VARIABLE nm_result)
if(NOT nm_result EQUAL 0)
  message(FATAL_ERROR "check_no_alloc: ${NM} -C ${LIBRARY} failed (${nm_result})")
endif()

# One symbol per line, name last: match the whole name, not substrings.
set(forbidden
  "[ \t](_?malloc|_?calloc|_?realloc|_?free|_malloc_r|_calloc_r|_realloc_r|_free_r)$"
  "operator new"
  "operator delete"
  "__cxa_throw"
  "__cxa_allocate_exception"
  "__cxa_begin_catch"
  "__gxx_personality"
  "typeinfo for")

string(REPLACE "\n" ";" lines "${symbols}")
set(found "")
foreach(line IN LISTS lines)
  foreach(pattern IN LISTS forbidden)
    if(line MATCHES "${pattern}")
      string(APPEND found "\n  ${line}")
      break()
    endif()
  endforeach()
endforeach()

if(found)
  message(FATAL_ERROR "check_no_alloc: ${LIBRARY} uses heap or exception symbols:${found}")
endif()
