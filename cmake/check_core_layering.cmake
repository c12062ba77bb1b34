# Checks the core's layering: run with
#   cmake -DCORE_DIR=components/core -DSTAMP=file -P cmake/check_core_layering.cmake
# The core is folders by domain, each including only itself and those below it:
#   math <- ins <- gnss <- filter <- integrity <- engine
# and none of them may include DDS, threads, clocks, I/O or logging. Fails (and the build with it)
# naming the file, the line and the include that breaks a rule; writes STAMP when all hold.
set(domains math ins gnss filter integrity engine)
set(forbidden_includes
  "fastdds/" "fastrtps/" "fastcdr/" "navbus_idl/" "spdlog/" "yaml-cpp/" "CLI/"
  "thread" "mutex" "condition_variable" "atomic" "future" "chrono" "ctime" "random"
  "iostream" "fstream" "cstdio" "stdio.h")
set(forbidden_calls "std::exit" "std::abort" "std::cout" "std::cerr" "printf(")

set(errors "")
file(GLOB_RECURSE files RELATIVE ${CORE_DIR}
     ${CORE_DIR}/include/navbus/core/*.hpp ${CORE_DIR}/src/*.cpp ${CORE_DIR}/src/*.hpp)
foreach(rel IN LISTS files)
  if(NOT rel MATCHES "^(include/navbus/core|src)/([a-z]+)/[^/]+$")
    string(APPEND errors "${rel}: not in a domain folder (${domains})\n")
    continue()
  endif()
  set(domain ${CMAKE_MATCH_2})
  list(FIND domains ${domain} rank)
  if(rank LESS 0)
    string(APPEND errors "${rel}: unknown domain '${domain}' (${domains})\n")
    continue()
  endif()
  file(STRINGS ${CORE_DIR}/${rel} lines)
  set(line_no 0)
  foreach(line IN LISTS lines)
    math(EXPR line_no "${line_no} + 1")
    if(line MATCHES "^#include \"([^\"]+)\"")
      set(target ${CMAKE_MATCH_1})
      if(NOT target MATCHES "^navbus/core/([a-z]+)/")
        string(APPEND errors "${rel}:${line_no}: includes \"${target}\", not a core header\n")
        continue()
      endif()
      list(FIND domains ${CMAKE_MATCH_1} target_rank)
      if(target_rank GREATER rank OR target_rank LESS 0)
        string(APPEND errors
               "${rel}:${line_no}: ${domain} includes \"${target}\" (a higher domain)\n")
      endif()
    elseif(line MATCHES "^#include <([^>]+)>")
      set(target ${CMAKE_MATCH_1})
      foreach(f IN LISTS forbidden_includes)
        string(FIND "${target}" "${f}" at)
        if(at EQUAL 0)
          string(APPEND errors "${rel}:${line_no}: includes <${target}> (no DDS, threads, clocks,"
                               " randomness, I/O or logging in the core)\n")
        endif()
      endforeach()
    else()
      foreach(c IN LISTS forbidden_calls)
        string(FIND "${line}" "${c}" at)
        if(NOT at EQUAL -1 AND NOT line MATCHES "^ *//")
          string(APPEND errors "${rel}:${line_no}: calls ${c} (the core returns, never prints or exits)\n")
        endif()
      endforeach()
    endif()
  endforeach()
endforeach()

if(errors)
  message(FATAL_ERROR "core layering (math <- ins <- gnss <- filter <- integrity <- engine):\n${errors}")
endif()
file(WRITE ${STAMP} "core layering holds\n")
