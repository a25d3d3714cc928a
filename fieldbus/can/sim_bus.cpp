#include "fieldbus/can/sim_bus.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace canmotion::can {

SimBus::Endpoint::Endpoint(SimBus& bus, std::string name, std::size_t capacity)
    : bus_(bus), name_(std::move(name)), rx_(capacity), capacity_(capacity), ev_(kEventCapacity) {}

// transmit() and deliver() are inlined into send(), the path of every frame;
// fault injection and the delayed frames take their own out-of-line paths.
[[gnu::always_inline]] inline SendResult SimBus::transmit(const Endpoint& from, const Frame& f) noexcept {
  if (state_ == BusState::kBusOff) [[unlikely]] return SendResult::kBusOff;
  if (!faults_.empty()) [[unlikely]] return transmit_with_faults(from, f);
  ++counters_.sent;
  deliver(&from, f, now_ns_);  // no fault injection: straight to the wire
  return SendResult::kOk;
}

// Inlined into deliver() (once per frame and endpoint).
[[gnu::always_inline]] inline void SimBus::Endpoint::push(const Frame& f, std::int64_t t_ns, std::size_t word,
                                                          std::uint64_t bit) noexcept {
  if (rx_count_ == capacity_) [[unlikely]] {
    ++counters_.rx_dropped;
    push_event(BusEvent{BusEvent::Kind::kRxOverflow, bus_.state_, 1, t_ns});
    return;
  }
  std::size_t tail = rx_head_ + rx_count_;  // < 2 * capacity: one wrap at most
  if (tail >= capacity_) tail -= capacity_;
  TimedFrame& slot = rx_[tail];
  std::memcpy(&slot.frame, &f, sizeof f);  // one 16-byte copy, not field by field
  slot.t_ns = t_ns;
  ++rx_count_;
  if (filtered_ && (openers_[word] & bit) != 0) {
    open_ = true;
    update_gate();
  }
  ++counters_.rx_frames;
}

[[gnu::always_inline]] inline void SimBus::deliver(const Endpoint* from, const Frame& frame, std::int64_t t_ns) noexcept {
  ++counters_.delivered;
  Frame f;
  std::memcpy(&f, &frame, sizeof f);  // read the sender's frame once, written straight into each ring
  if (tap_) [[unlikely]] tap_(TimedFrame{f, t_ns}, name_);
  if ((f.flags & (kExtended | kError)) != 0 || f.id >= 2048) [[unlikely]] {
    // Extended and error frames reach only the endpoints that take every frame now.
    for (auto& ep : endpoints_) {
      Endpoint& e = *ep;
      if (&e != from && e.gate_ == Endpoint::kAllIds.data()) e.push(f, t_ns, 0, 0);
    }
    return;
  }
  // Where the id sits in the endpoints' id sets, once for all.
  const std::size_t word = f.id >> 6;
  const std::uint64_t bit = std::uint64_t{1} << (f.id & 63u);
  for (auto& ep : endpoints_) {
    Endpoint& e = *ep;
    if (&e == from || (e.gate_[word] & bit) == 0) continue;
    e.push(f, t_ns, word, bit);
  }
}

[[gnu::cold, gnu::noinline]] void SimBus::Endpoint::link_refused() noexcept {
  ++counters_.tx_errors;
  if (!link_down_) {
    link_down_ = true;
    push_event(BusEvent{BusEvent::Kind::kLinkDown, bus_.state_, ENETDOWN, bus_.now_ns_});
  }
}

SendResult SimBus::Endpoint::send(const Frame& frame) noexcept {
  if (cut_) [[unlikely]] {
    link_refused();
    return SendResult::kError;
  }
  const SendResult r = bus_.transmit(*this, frame);
  if (r == SendResult::kOk) {
    ++counters_.tx_frames;
    if (link_down_) [[unlikely]] {
      link_down_ = false;
      push_event(BusEvent{BusEvent::Kind::kLinkUp, bus_.state_, 0, bus_.now_ns_});
    }
  } else {
    ++counters_.tx_errors;
  }
  return r;
}

std::size_t SimBus::Endpoint::receive(std::span<TimedFrame> out) noexcept {
  std::size_t n = 0;
  while (n < out.size() && rx_count_ > 0) {
    out[n++] = rx_[rx_head_];
    if (++rx_head_ == capacity_) rx_head_ = 0;
    --rx_count_;
  }
  // An empty ring starts again at its first slot: the few slots a cycle
  // uses stay in the cache instead of sweeping the whole ring.
  if (rx_count_ == 0) {
    rx_head_ = 0;
    open_ = false;  // the owner has seen the opener (see set_accept)
    update_gate();
  }
  return n;
}

void SimBus::Endpoint::consume(std::size_t n) noexcept {
  n = std::min(n, rx_count_);
  rx_head_ += n;
  if (rx_head_ >= capacity_) rx_head_ -= capacity_;
  rx_count_ -= n;
  if (rx_count_ == 0) {  // as in receive()
    rx_head_ = 0;
    open_ = false;
    update_gate();
  }
}

std::size_t SimBus::Endpoint::poll_events(std::span<BusEvent> out) noexcept {
  std::size_t n = 0;
  while (n < out.size() && ev_count_ > 0) {
    out[n++] = ev_[ev_head_];
    ev_head_ = (ev_head_ + 1) % ev_.size();
    --ev_count_;
  }
  return n;
}

BusState SimBus::Endpoint::state() const noexcept { return bus_.state_; }

void SimBus::Endpoint::push_event(const BusEvent& e) noexcept {
  if (ev_count_ == ev_.size()) {
    ev_head_ = (ev_head_ + 1) % ev_.size();  // drop the oldest
    --ev_count_;
  }
  ev_[(ev_head_ + ev_count_) % ev_.size()] = e;
  ++ev_count_;
}

SimBus::SimBus(std::string name) : name_(std::move(name)) {}

SimBus::Endpoint& SimBus::add_endpoint(std::string name, std::size_t rx_capacity) {
  endpoints_.push_back(std::unique_ptr<Endpoint>(new Endpoint(*this, std::move(name), std::max<std::size_t>(rx_capacity, 1))));
  return *endpoints_.back();
}

void SimBus::add_fault(const SimFault& f) { faults_.push_back(Rule{f, 0, 0}); }

void SimBus::set_time(std::int64_t now_ns) noexcept {
  if (now_ns < now_ns_) return;
  now_ns_ = now_ns;
  while (!delayed_.empty() && delayed_.front().due_ns <= now_ns_) {
    const Delayed d = delayed_.front();
    delayed_.pop_front();
    deliver(d.from, d.frame, d.due_ns);
  }
}

void SimBus::set_state(BusState s) noexcept {
  state_ = s;
  for (auto& ep : endpoints_) ep->push_event(BusEvent{BusEvent::Kind::kStateChanged, s, 0, now_ns_});
}

SendResult SimBus::transmit_with_faults(const Endpoint& from, const Frame& f) noexcept {
  ++counters_.sent;
  Frame frame = f;
  for (Rule& r : faults_) {
    if (r.fault.cob_id != SimFault::kAnyId && r.fault.cob_id != f.id) continue;
    ++r.seen;
    if (r.seen <= r.fault.skip) continue;
    if (r.fault.count != 0 && r.acted >= r.fault.count) continue;
    ++r.acted;
    switch (r.fault.action) {
      case SimFault::Action::kDrop:
        ++counters_.dropped;
        return SendResult::kOk;  // the sender cannot tell
      case SimFault::Action::kDelay: {
        ++counters_.delayed;
        Delayed d{now_ns_ + r.fault.delay_ns, seq_++, &from, frame};
        // Delays are only used by fault-injection tests; the deque insert may allocate.
        auto it = std::upper_bound(delayed_.begin(), delayed_.end(), d, [](const Delayed& a, const Delayed& b) {
          return a.due_ns < b.due_ns || (a.due_ns == b.due_ns && a.seq < b.seq);
        });
        delayed_.insert(it, d);
        return SendResult::kOk;
      }
      case SimFault::Action::kCorrupt:
        ++counters_.corrupted;
        if (r.fault.byte < kMaxPayload) frame.data[r.fault.byte] ^= r.fault.xor_mask;
        if (r.fault.new_len >= 0) frame.len = static_cast<std::uint8_t>(std::min<int>(r.fault.new_len, kMaxPayload));
        break;
    }
    break;
  }
  deliver(&from, frame, now_ns_);
  return SendResult::kOk;
}

}  // namespace canmotion::can
