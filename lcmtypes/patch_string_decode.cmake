# Closes a hole in the C++ decoder that lcm-gen 1.3 writes for every string field:
#     if(__name_len__ > maxlen - pos) return -1;
#     this->name.assign(buf + offset + pos, __name_len__ - 1);
# A length of INT32_MIN from the wire passes the check, and `__name_len__ - 1` overflows (undefined;
# in practice INT32_MAX: a 2 GB read past the message). Found by fuzz target lcm_messages. A
# string on the wire is at least its NUL terminator, so a length below 1 is refused as malformed.
# Run after lcm-gen on the generated headers: cmake -DDIR=<folder of *.hpp> -P patch_string_decode.cmake
# Fails when a header decodes a string without the expected check (another lcm-gen version):
# then look at the generated code again.
file(GLOB _headers ${DIR}/*.hpp)
foreach(h ${_headers})
  file(READ ${h} _text)
  string(REGEX REPLACE "if\\((__[A-Za-z0-9_]+_len__) > maxlen - pos\\) return -1;"
         "if(\\1 < 1 || \\1 > maxlen - pos) return -1;" _patched "${_text}")
  string(REGEX MATCHALL "_len__ - 1\\)" _assigns "${_patched}")
  string(REGEX MATCHALL "_len__ < 1 \\|\\|" _checks "${_patched}")
  list(LENGTH _assigns _n_assigns)
  list(LENGTH _checks _n_checks)
  if(NOT _n_assigns EQUAL _n_checks)
    message(FATAL_ERROR "${h}: ${_n_assigns} string decodes but ${_n_checks} length checks patched")
  endif()
  if(NOT _patched STREQUAL _text)
    file(WRITE ${h} "${_patched}")
  endif()
endforeach()
