#include "systems/io/line_fields.h"

#include "systems/io/io_limits.h"
#include "systems/io/text_parse.h"

namespace rivulet::io {

bool LineFields::next() {
    while (in_.read_line(text_, kMaxDataLine)) {
        split_fields(text_, fields_);
        if (!fields_.empty()) return true;
    }
    fields_.clear();
    return false;
}

}  // namespace rivulet::io
