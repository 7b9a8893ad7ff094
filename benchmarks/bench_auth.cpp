// The cost of authenticating one bus message (DESIGN §4, §7): the Ed25519 signature a coordinator
// puts on every message it publishes (libsodium's crypto_sign_detached, as middleware::Signer
// does) and the check every receiver makes before it believes one (crypto_sign_verify_detached,
// as Keyring::verify does). Ed25519 hashes the whole message, so both grow with its size: 256
// bytes is about one state update with its roots, 4 KiB a batch. Counter bytes_per_second.

#include <benchmark/benchmark.h>

#include <sodium.h>

#include <array>
#include <cstddef>
#include <vector>

namespace {

struct Keys {
  std::array<unsigned char, crypto_sign_PUBLICKEYBYTES> pk{};
  std::array<unsigned char, crypto_sign_SECRETKEYBYTES> sk{};
  Keys() {
    if (::sodium_init() < 0) return;
    ::crypto_sign_keypair(pk.data(), sk.data());
  }
};

std::vector<unsigned char> message(std::size_t bytes) {
  std::vector<unsigned char> m(bytes);
  for (std::size_t i = 0; i < bytes; ++i) m[i] = static_cast<unsigned char>(i * 31u + 7u);
  return m;
}

void BM_Ed25519Sign(benchmark::State& state) {
  const Keys keys;
  const auto m = message(static_cast<std::size_t>(state.range(0)));
  std::array<unsigned char, crypto_sign_BYTES> signature{};
  for (auto _ : state) {
    ::crypto_sign_detached(signature.data(), nullptr, m.data(), m.size(), keys.sk.data());
    benchmark::DoNotOptimize(signature);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_Ed25519Sign)->Arg(256)->Arg(4096)->Unit(benchmark::kMicrosecond);

void BM_Ed25519Verify(benchmark::State& state) {
  const Keys keys;
  const auto m = message(static_cast<std::size_t>(state.range(0)));
  std::array<unsigned char, crypto_sign_BYTES> signature{};
  ::crypto_sign_detached(signature.data(), nullptr, m.data(), m.size(), keys.sk.data());
  for (auto _ : state) {
    const int bad = ::crypto_sign_verify_detached(signature.data(), m.data(), m.size(), keys.pk.data());
    if (bad != 0) state.SkipWithError("a genuine signature was refused");
    benchmark::DoNotOptimize(bad);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
// 25,600 bytes: about the heartbeat of a coordinator of 1,000 interfaces (it lists every stream).
BENCHMARK(BM_Ed25519Verify)->Arg(256)->Arg(4096)->Arg(25600)->Unit(benchmark::kMicrosecond);

}  // namespace

#if SAFECASS_BENCH_BUS_SEAL
// The bus as it authenticates messages now (middleware/src/auth.hpp): state updates, event
// records and resync requests are sealed, one 16-byte BLAKE2b tag per member keyed with the key
// the sender shares with it, of one BLAKE2b digest of the message; heartbeats alone keep the
// Ed25519 signature. Arg: the receivers (the keyring holds them and the sender). A 256-byte body.
#include <cstdlib>
#include <string>

#include "auth.hpp"
#include "bus_link.hpp"
#include "safecass/middleware/keys.hpp"

namespace {

struct Bus {
  std::vector<safecass::middleware::Signer> members;  // [0] sends, the others receive
  explicit Bus(std::size_t receivers) {
    safecass::spec::SystemSpec system;
    system.name = "bench";
    for (std::size_t i = 0; i < receivers; ++i) {
      system.coordinators.emplace_back("m" + std::to_string(i), std::vector<std::string>{});
    }
    char dir[] = "/tmp/safecass-bench-keys-XXXXXX";
    if (::mkdtemp(dir) == nullptr) return;
    if (!safecass::middleware::create_bus_keys(system, dir, safecass::middleware::KeyOptions::replacing())) return;
    auto keyring = safecass::middleware::Keyring::load(dir);
    if (!keyring) return;
    // The supervisor sends; every coordinator receives.
    if (auto s = safecass::middleware::Signer::load(dir, "supervisor", *keyring)) members.push_back(std::move(*s));
    for (const auto& [name, _] : system.coordinators) {
      if (auto s = safecass::middleware::Signer::load(dir, name, *keyring)) members.push_back(std::move(*s));
    }
    (void)std::system(("rm -rf " + std::string(dir)).c_str());
  }
};

Ice::ByteSeq body256() {
  const auto m = message(256);
  return Ice::ByteSeq(m.begin(), m.end());
}

// What one message costs the bus: sealed once by its sender, opened by one receiver.
void BM_BusSealAndOpen(benchmark::State& state) {
  const Bus bus(static_cast<std::size_t>(state.range(0)));
  if (bus.members.size() != static_cast<std::size_t>(state.range(0)) + 1) {
    state.SkipWithError("cannot create the bench keys");
    return;
  }
  const Ice::ByteSeq body = body256();
  for (auto _ : state) {
    const safecass::wire::Signed m = bus.members[0].seal("state", body);
    const bool ok = bus.members[1].opens(m);
    if (!ok) state.SkipWithError("a genuine seal was refused");
    benchmark::DoNotOptimize(ok);
  }
}
BENCHMARK(BM_BusSealAndOpen)->Arg(1)->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);

// What a forged message costs its receiver: the digest and one tag, then refused.
void BM_BusRefuseForged(benchmark::State& state) {
  const Bus bus(4);
  if (bus.members.size() != 5) {
    state.SkipWithError("cannot create the bench keys");
    return;
  }
  safecass::wire::Signed m = bus.members[0].seal("state", body256());
  for (auto& b : m.tags) b ^= 1;  // a forger knows none of the tags
  for (auto _ : state) {
    const bool ok = bus.members[1].opens(m) || bus.members[2].opens(m);
    if (ok) state.SkipWithError("a forged seal was accepted");
    benchmark::DoNotOptimize(ok);
  }
  state.SetLabel("two receivers each refuse it; time / 2 per receiver");
}
BENCHMARK(BM_BusRefuseForged)->Unit(benchmark::kMicrosecond);

// What a process pays to know its own heartbeat when it comes back (BusLink::heard_own): compared
// byte for byte with the last ones it sent (SentHeartbeats, 8 kept) instead of its signature
// checked (BM_Ed25519Verify at the same size). Arg: the body's bytes; the newest is looked for,
// as a heartbeat that came back within its period is.
void BM_BusOwnHeartbeatKnown(benchmark::State& state) {
  const auto bytes = message(static_cast<std::size_t>(state.range(0)));
  safecass::middleware::SentHeartbeats sent;
  safecass::wire::Signed newest;
  for (std::size_t k = 0; k < safecass::middleware::SentHeartbeats::kKept; ++k) {
    newest.signer = "robot";
    newest.kind = "heartbeat";
    newest.body.assign(bytes.begin(), bytes.end());
    newest.body[0] = static_cast<Ice::Byte>(k);
    newest.signature.assign(64, static_cast<Ice::Byte>(k));
    sent.sent(newest);
  }
  for (auto _ : state) {
    const bool known = sent.holds(newest);
    if (!known) state.SkipWithError("the newest heartbeat sent was not known");
    benchmark::DoNotOptimize(known);
  }
}
BENCHMARK(BM_BusOwnHeartbeatKnown)->Arg(256)->Arg(25600)->Unit(benchmark::kMicrosecond);

}  // namespace
#endif
