// The system's TLS certificates (certificates.hpp): a CA and one certificate per member, made with
// OpenSSL's library, in memory; auth.cpp writes them with the key files.

#include "certificates.hpp"

#include <openssl/bn.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/rand.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <memory>

namespace safecass::middleware {

namespace {

template <typename T, void (*Free)(T*)>
struct Deleter {
  void operator()(T* p) const noexcept { Free(p); }
};
using Key = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY, EVP_PKEY_free>>;
using Cert = std::unique_ptr<X509, Deleter<X509, X509_free>>;
using Bio = std::unique_ptr<BIO, Deleter<BIO, BIO_free_all>>;

constexpr long kCaDays = 3650;
constexpr long kMemberDays = 825;

/// OpenSSL's last error, for a message.
std::string openssl_error(std::string_view what) {
  char buffer[256] = {};
  ERR_error_string_n(ERR_get_error(), buffer, sizeof buffer);
  ERR_clear_error();
  return "TLS certificate: " + std::string(what) + " failed (" + buffer + ")";
}

tl::unexpected<Error> fail_openssl(std::string_view what) { return fail(ErrorCode::Io, openssl_error(what)); }

Bio memory_of(const std::string& text) { return Bio(BIO_new_mem_buf(text.data(), static_cast<int>(text.size()))); }

std::string text_of(BIO* bio) {
  char* data = nullptr;
  const long n = BIO_get_mem_data(bio, &data);
  return n > 0 ? std::string(data, static_cast<std::size_t>(n)) : std::string();
}

bool add_extension(X509* cert, X509* issuer, int nid, const std::string& value) {
  X509V3_CTX ctx;
  X509V3_set_ctx(&ctx, issuer, cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value.c_str());
  if (ext == nullptr) return false;
  const bool ok = X509_add_ext(cert, ext, -1) == 1;
  X509_EXTENSION_free(ext);
  return ok;
}

/// A certificate of `key` named `common_name`, valid from an hour ago for `days` (the hour
/// absorbs clock differences between hosts), with a random 64-bit serial.
Cert new_certificate(EVP_PKEY* key, const std::string& common_name, long days) {
  Cert cert(X509_new());
  if (!cert) return cert;
  unsigned char serial[8];
  BIGNUM* bn = RAND_bytes(serial, sizeof serial) == 1 ? BN_bin2bn(serial, sizeof serial, nullptr) : nullptr;
  const bool ok =
      bn != nullptr && BN_to_ASN1_INTEGER(bn, X509_get_serialNumber(cert.get())) != nullptr &&
      X509_set_version(cert.get(), 2) == 1 && X509_gmtime_adj(X509_getm_notBefore(cert.get()), -3600) != nullptr &&
      X509_gmtime_adj(X509_getm_notAfter(cert.get()), days * 24 * 3600) != nullptr &&
      X509_set_pubkey(cert.get(), key) == 1 &&
      X509_NAME_add_entry_by_txt(X509_get_subject_name(cert.get()), "CN", MBSTRING_UTF8,
                                 reinterpret_cast<const unsigned char*>(common_name.c_str()), -1, -1, 0) == 1;
  BN_free(bn);
  if (!ok) cert.reset();
  return cert;
}

[[nodiscard]] Expected<Pem> to_pem(X509* cert, EVP_PKEY* key) {
  Bio cert_out(BIO_new(BIO_s_mem()));
  Bio key_out(BIO_new(BIO_s_mem()));
  if (!cert_out || !key_out || PEM_write_bio_X509(cert_out.get(), cert) != 1 ||
      PEM_write_bio_PrivateKey(key_out.get(), key, nullptr, nullptr, 0, nullptr, nullptr) != 1) {
    return fail_openssl("writing PEM");
  }
  return Pem{text_of(cert_out.get()), text_of(key_out.get())};
}

}  // namespace

[[nodiscard]] Expected<Pem> make_ca(std::string_view system_name) {
  Key key(EVP_EC_gen("P-256"));
  if (!key) return fail_openssl("making the CA's key");
  Cert cert = new_certificate(key.get(), "SAFECASS CA of system " + std::string(system_name), kCaDays);
  if (!cert || X509_set_issuer_name(cert.get(), X509_get_subject_name(cert.get())) != 1 ||
      !add_extension(cert.get(), cert.get(), NID_basic_constraints, "critical,CA:TRUE,pathlen:0") ||
      !add_extension(cert.get(), cert.get(), NID_key_usage, "critical,keyCertSign,cRLSign") ||
      !add_extension(cert.get(), cert.get(), NID_subject_key_identifier, "hash") ||
      X509_sign(cert.get(), key.get(), EVP_sha256()) == 0) {
    return fail_openssl("making the CA");
  }
  return to_pem(cert.get(), key.get());
}

[[nodiscard]] Expected<Pem> make_certificate(const Pem& ca, const std::string& name,
                                             const std::vector<std::string>& addresses) {
  Bio ca_cert_in = memory_of(ca.certificate);
  Bio ca_key_in = memory_of(ca.key);
  Cert ca_cert(ca_cert_in ? PEM_read_bio_X509(ca_cert_in.get(), nullptr, nullptr, nullptr) : nullptr);
  Key ca_key(ca_key_in ? PEM_read_bio_PrivateKey(ca_key_in.get(), nullptr, nullptr, nullptr) : nullptr);
  if (!ca_cert || !ca_key) return fail_openssl("reading the CA (ca.pem, ca.key)");
  if (X509_check_private_key(ca_cert.get(), ca_key.get()) != 1) {
    return fail(ErrorCode::InvalidArgument, "TLS certificate: ca.key is not the key of ca.pem");
  }
  Key key(EVP_EC_gen("P-256"));
  if (!key) return fail_openssl("making the key of '" + name + "'");
  std::string alt_names = "IP:127.0.0.1,DNS:localhost";
  for (const std::string& a : addresses) alt_names += "," + a;
  Cert cert = new_certificate(key.get(), name, kMemberDays);
  if (!cert || X509_set_issuer_name(cert.get(), X509_get_subject_name(ca_cert.get())) != 1 ||
      !add_extension(cert.get(), ca_cert.get(), NID_basic_constraints, "critical,CA:FALSE") ||
      !add_extension(cert.get(), ca_cert.get(), NID_key_usage, "critical,digitalSignature") ||
      !add_extension(cert.get(), ca_cert.get(), NID_ext_key_usage, "serverAuth,clientAuth") ||
      !add_extension(cert.get(), ca_cert.get(), NID_authority_key_identifier, "keyid:always")) {
    return fail_openssl("making the certificate of '" + name + "'");
  }
  if (!add_extension(cert.get(), ca_cert.get(), NID_subject_alt_name, alt_names)) {
    return fail(
        ErrorCode::InvalidArgument,
        "TLS certificate: '" + alt_names + "' is not a list of addresses (IP:ADDRESS or DNS:NAME, comma-separated)");
  }
  if (X509_sign(cert.get(), ca_key.get(), EVP_sha256()) == 0) return fail_openssl("signing '" + name + "'");
  return to_pem(cert.get(), key.get());
}

bool signed_by(const std::string& certificate, const std::string& ca_certificate) {
  Bio cert_in = memory_of(certificate);
  Bio ca_in = memory_of(ca_certificate);
  Cert cert(cert_in ? PEM_read_bio_X509(cert_in.get(), nullptr, nullptr, nullptr) : nullptr);
  Cert ca(ca_in ? PEM_read_bio_X509(ca_in.get(), nullptr, nullptr, nullptr) : nullptr);
  if (!cert || !ca) {
    ERR_clear_error();
    return false;
  }
  Key ca_key(X509_get_pubkey(ca.get()));
  const bool ok =
      ca_key && X509_verify(cert.get(), ca_key.get()) == 1 && X509_check_issued(ca.get(), cert.get()) == X509_V_OK;
  ERR_clear_error();
  return ok;
}

}  // namespace safecass::middleware
