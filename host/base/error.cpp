#include "base/error.hpp"

#include <CL/cl.h>

namespace candela {

const char* cl_error_name(int code) {
  switch (code) {
#define CASE(x) \
  case x:       \
    return #x;
    CASE(CL_DEVICE_NOT_FOUND)
    CASE(CL_DEVICE_NOT_AVAILABLE)
    CASE(CL_COMPILER_NOT_AVAILABLE)
    CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    CASE(CL_OUT_OF_RESOURCES)
    CASE(CL_OUT_OF_HOST_MEMORY)
    CASE(CL_BUILD_PROGRAM_FAILURE)
    CASE(CL_INVALID_VALUE)
    CASE(CL_INVALID_DEVICE)
    CASE(CL_INVALID_BINARY)
    CASE(CL_INVALID_BUILD_OPTIONS)
    CASE(CL_INVALID_PROGRAM)
    CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    CASE(CL_INVALID_KERNEL_NAME)
    CASE(CL_INVALID_KERNEL_ARGS)
    CASE(CL_INVALID_ARG_SIZE)
    CASE(CL_INVALID_ARG_VALUE)
    CASE(CL_INVALID_WORK_GROUP_SIZE)
    CASE(CL_INVALID_GLOBAL_WORK_SIZE)
    CASE(CL_INVALID_BUFFER_SIZE)
    CASE(CL_INVALID_MEM_OBJECT)
    CASE(CL_INVALID_COMMAND_QUEUE)
    CASE(CL_INVALID_CONTEXT)
    CASE(CL_INVALID_OPERATION)
    CASE(CL_INVALID_PLATFORM)
#undef CASE
    case -1001:
      return "CL_PLATFORM_NOT_FOUND_KHR";
    default:
      return "unknown OpenCL error";
  }
}

std::string cl_error_message(const std::string& what, int code) {
  std::string msg = "OpenCL error in " + what + ": " + cl_error_name(code) + " (" + std::to_string(code) + ")";
  if (code == CL_MEM_OBJECT_ALLOCATION_FAILURE || code == CL_OUT_OF_RESOURCES || code == CL_OUT_OF_HOST_MEMORY ||
      code == CL_INVALID_BUFFER_SIZE)
    msg +=
        ": the device ran out of memory or resources (or, on some GPUs, the kernel faulted "
        "or hit a watchdog); try a smaller image or scene, or another --device";
  return msg;
}

}  // namespace candela
