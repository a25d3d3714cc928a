#include "fieldbus/canopen/tx_queue.hpp"

#include <cstdio>

namespace canmotion::canopen {

TxQueueCheck check_tx_queue(std::uint32_t current, const TxBurst& burst, bool may_raise) noexcept {
  TxQueueCheck c;
  c.current = current;
  c.burst = burst;
  c.needed = burst.frames();
  // 0: no queue at all (a virtual interface such as vcan hands each frame
  // straight to its driver): nothing to overflow.
  if (current == 0 || current >= c.needed) c.action = TxQueueCheck::Action::kOk;
  else c.action = may_raise ? TxQueueCheck::Action::kRaise : TxQueueCheck::Action::kRefuse;
  return c;
}

std::string TxQueueCheck::message(std::string_view ifname) const {
  const int n = static_cast<int>(ifname.size());
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "interface %.*s has txqueuelen %u but one cycle writes up to %u frames (%u RPDO%s, 1 SYNC, %u SDO%s, "
                "%u heartbeat, 1 NMT): frames beyond the queue are dropped (ENOBUFS). Run `ip link set %.*s "
                "txqueuelen %u` as root before canmotiond, or give canmotiond CAP_NET_ADMIN to raise it itself",
                n, ifname.data(), current, needed, burst.rpdos, burst.rpdos == 1 ? "" : "s", burst.sdo_nodes,
                burst.sdo_nodes == 1 ? "" : "s", burst.master_heartbeat ? 1u : 0u, n, ifname.data(), needed);
  return buf;
}

}  // namespace canmotion::canopen
