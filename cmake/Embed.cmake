# skybake_embed_text(<output.cpp> <variable> <files...>): generate a C++
# source holding the files' text as skybake::<variable> (see EmbedText.cmake).
function(skybake_embed_text output variable)
  # A list would be split by add_custom_command; pass it '|'-joined.
  string(JOIN "|" inputs ${ARGN})
  add_custom_command(
    OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DOUTPUT=${output} -DVARIABLE=${variable} "-DINPUTS=${inputs}"
            -P ${PROJECT_SOURCE_DIR}/cmake/EmbedText.cmake
    DEPENDS ${ARGN} ${PROJECT_SOURCE_DIR}/cmake/EmbedText.cmake
    COMMENT "Embedding ${variable}"
    VERBATIM)
endfunction()
