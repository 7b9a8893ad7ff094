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
BENCHMARK(BM_Ed25519Verify)->Arg(256)->Arg(4096)->Unit(benchmark::kMicrosecond);

}  // namespace
