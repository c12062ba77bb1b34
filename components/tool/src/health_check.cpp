#include "navbus/tool/health_check.hpp"

#include <cstdio>
#include <optional>

#include <navbus_idl/HealthPubSubTypes.h>

#include "navbus/bus/app.hpp"
#include "navbus/bus/topics.hpp"
#include "navbus/records/message_fields.hpp"
#include "navbus/tool/spin.hpp"

namespace navbus::tool {

int runHealthCommand(const bus::Participant::Options& participant, const HealthCheckOptions& o,
                     bus::ShutdownSignal& shutdown) {
  bus::Participant p(participant, shutdown);
  std::optional<navbus::Health> latest;
  p.subscribe<navbus::HealthPubSubType>(bus::topic::kHealth, bus::profile::kHealthReader,
                                        [&](const navbus::Health& h, const auto&) {
                                          if (h.participant().to_string() == o.participant)
                                            latest = h;
                                        });
  const auto working = [&] {
    return latest &&
           (latest->state() == navbus::STATE_RUNNING || latest->state() == navbus::STATE_DEGRADED);
  };
  spinUntil(p, o.timeout_s, working);
  p.finish();
  if (!latest) {
    std::printf("%s: no health report within %g s\n", o.participant.c_str(), o.timeout_s);
    return bus::kExitRuntimeError;
  }
  std::printf("%s: %s (report %llu)\n", o.participant.c_str(), records::enumName(latest->state()),
              static_cast<unsigned long long>(latest->seq()));
  return working() ? bus::kExitOk : bus::kExitRuntimeError;
}

}  // namespace navbus::tool
