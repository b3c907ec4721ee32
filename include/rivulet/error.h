#pragma once
// The one exception type of Rivulet's public API. Every function of <rivulet/...> reports bad input, bad
// settings and unreadable files by throwing rivulet::Error, whose what() is the message the `rivulet`
// command line prints after "rivulet: error: " for the same mistake.
#include <stdexcept>

namespace rivulet {

class Error : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

}  // namespace rivulet
