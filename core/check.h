#pragma once

#include <sstream>
#include <string>

#include "core/errors.h"

namespace curvesfm::internal {

/// Collects the context streamed after a failed CURVESFM_CHECK.
class CheckMessage {
 public:
  CheckMessage(const char* file, int line, const char* condition) {
    stream_ << "CheckError: " << file << ":" << line << ": check failed: " << condition;
  }
  template <class T>
  CheckMessage& operator<<(const T& value) {
    if (!has_context_) stream_ << ": ";
    has_context_ = true;
    stream_ << value;
    return *this;
  }
  std::string str() const { return stream_.str(); }

 private:
  std::ostringstream stream_;
  bool has_context_ = false;
};

/// `&` binds looser than `<<`, so the whole message is built before this throws.
struct CheckThrower {
  [[noreturn]] void operator&(const CheckMessage& message) const { throw CheckError(message.str()); }
};

}  // namespace curvesfm::internal

/// Throws curvesfm::CheckError when `condition` is false, with the streamed context:
///   CURVESFM_CHECK(m >= 4) << "a cubic fit needs 4 points, got " << m;
/// Programmer errors throw (never abort) so that tests can EXPECT_THROW them.
#define CURVESFM_CHECK(condition)           \
  (condition) ? static_cast<void>(0)        \
              : ::curvesfm::internal::CheckThrower() & \
                    ::curvesfm::internal::CheckMessage(__FILE__, __LINE__, #condition)
