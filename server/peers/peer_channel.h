// The channel a coordinating replica sends its pair jobs on (k4reg-server --peers): round robin over every address
// the target resolves to, no message size limit of its own (--max-pair-mb bounds what is sent), keepalive so a
// peer that vanishes without closing its connections (a node lost) is noticed within 30 s.
// With TLS on, replicas speak TLS to each other too: they present their own certificate (so mutual TLS between
// replicas works) and trust the --tls-client-ca when one is given, else their own certificate (one self-signed
// certificate for the deployment). The certificate must name the host of the --peers target.
#pragma once

#include <grpcpp/channel.h>

#include <memory>
#include <optional>
#include <string>

#include "security/tls.h"

namespace k4reg::service {

std::shared_ptr<grpc::Channel> make_peer_channel(const std::string& target, const std::optional<TlsConfig>& tls);

}  // namespace k4reg::service
