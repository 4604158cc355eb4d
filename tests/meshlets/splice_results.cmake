# cmake -DRESULTS=file.md -DDOC=docs/benchmarks-meshlets.md -P splice_results.cmake
# Replaces everything after the "<!-- results below are generated -->" line of DOC with RESULTS,
# so the hand-written analysis above it survives a rerun of the benchmark.
set(marker "<!-- results below are generated -->")
file(READ ${RESULTS} results)
if(EXISTS ${DOC})
  file(READ ${DOC} doc)
  string(FIND "${doc}" "${marker}" at)
  if(at GREATER -1)
    string(SUBSTRING "${doc}" 0 ${at} doc)
  endif()
else()
  set(doc "")
endif()
file(WRITE ${DOC} "${doc}${marker}\n\n${results}")
message(STATUS "wrote ${DOC}")
