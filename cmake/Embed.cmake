# skybake_embed_text(<output.cpp> <variable> <files...>): generate a C++
# source holding the files' text as skybake::<variable> (see EmbedText.cmake).
function(skybake_embed_text output variable)
  add_custom_command(
    OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DOUTPUT=${output} -DVARIABLE=${variable} "-DINPUTS=${ARGN}"
            -P ${PROJECT_SOURCE_DIR}/cmake/EmbedText.cmake
    DEPENDS ${ARGN} ${PROJECT_SOURCE_DIR}/cmake/EmbedText.cmake
    COMMENT "Embedding ${variable}"
    # Without VERBATIM the ';' of the INPUTS list reaches the shell unquoted
    # and splits the command as soon as there is more than one file.
    VERBATIM)
endfunction()
