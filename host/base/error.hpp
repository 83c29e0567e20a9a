// One exception type for every user-facing failure: its message is printed as is.
#pragma once

#include <stdexcept>
#include <string>

namespace candela {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// Name of an OpenCL error code, e.g. "CL_OUT_OF_RESOURCES"
const char* cl_error_name(int code);

// Readable message for an OpenCL failure in `what` (a function or an action)
std::string cl_error_message(const std::string& what, int code);

}  // namespace candela
