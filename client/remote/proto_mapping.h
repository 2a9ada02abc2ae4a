// Parameters -> k4reg.v1 on the client side (answers come back through proto/convert/messages_to_core.h).
#pragma once

#include "k4reg/registration/registration.h"
#include "k4reg/v1/registration.pb.h"
#include "commands/registration_flags.h"

namespace k4reg::cli {

// Only the parameters whose flags were given are set; the rest stay unset, so the server's defaults apply
// (the same values as the local defaults, except threads: the server's --job-threads, not all cores).
v1::RegistrationParams params_to_proto(const RegistrationParams& params, const RegistrationFlags& flags);

}  // namespace k4reg::cli
