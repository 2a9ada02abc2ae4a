// cpp-httplib, included only through this header: it pulls in <resolv.h>, whose `_res` macro breaks Eigen
// headers included after it (Eigen names parameters `_res`), and nothing here uses the resolver state.
#pragma once

#include <httplib.h>

#undef _res
