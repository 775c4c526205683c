// The headers as a C++98 compiler takes them, pedantic: built with the
// host preset, so a C-only construct in a header fails the build.
#include "servobus/servobus_posix.h"

int servobus_header_cxx98(void);
int servobus_header_cxx98(void)
{
    sb_ping_request r = {1};
    return r.id;
}
