#pragma once
// One exception type for every file problem (bad content, missing file, failed write), so callers that
// load user data can catch a single type and show its message, which always starts with the file's path.
#include <stdexcept>

namespace rivulet {

class FileFormatError : public std::runtime_error {
  public:
    using runtime_error::runtime_error;
};

}  // namespace rivulet
