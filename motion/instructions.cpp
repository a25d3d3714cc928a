#include "motion/instructions.hpp"

#include <array>
#include <utility>

#include "motion/instr/ctx.hpp"

namespace canmotion::motion {
namespace {

using Decoder = Params (*)(const Operands&) noexcept;

template <class P>
Params decode_as(const Operands& q) noexcept { return P::decode(q); }
Params decode_not_executable(const Operands& q) noexcept { return NotExecutableParams{q.r.instr}; }

template <class P>
concept Executable = requires { P::kInstr; };

/// The decoder of every instruction, by Instr: the params type whose kInstr
/// it is (checked: exactly the instructions the signature table marks
/// executable have one, and only one).
template <std::size_t... I>
consteval std::array<Decoder, kInstrCount> make_decoders(std::index_sequence<I...>) {
  std::array<Decoder, kInstrCount> t{};
  std::array<int, kInstrCount> n{};
  auto add = [&]<class P>(std::type_identity<P>) {
    if constexpr (Executable<P>) {
      t[static_cast<std::size_t>(P::kInstr)] = &decode_as<P>;
      ++n[static_cast<std::size_t>(P::kInstr)];
    }
  };
  (add(std::type_identity<std::variant_alternative_t<I, Params>>{}), ...);
  for (std::size_t i = 0; i < kInstrCount; ++i) {
    if (n[i] > 1) throw "two params types for one instruction";
    if (signature(static_cast<Instr>(i)).executable != (n[i] == 1))
      throw "an executable instruction without params (or params of one that is not executable)";
    if (n[i] == 0) t[i] = &decode_not_executable;
  }
  return t;
}
constexpr std::array<Decoder, kInstrCount> kDecoders =
    make_decoders(std::make_index_sequence<std::variant_size_v<Params>>{});

}  // namespace

Params decode(const Request& r) noexcept { return kDecoders[static_cast<std::size_t>(r.instr)](Operands{r}); }

Err start(Ctx&, const NotExecutableParams&) noexcept { return Err::InstructionNotSupported; }

}  // namespace canmotion::motion
