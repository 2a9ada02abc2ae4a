#include "k4reg/util/cancellation.h"

#include "k4reg/util/error.h"

namespace k4reg {

void CancellationToken::throw_if_stopped() const {
  if (cancelled()) fail(ErrorCode::kCancelled, "registration cancelled");
  if (deadline_passed()) fail(ErrorCode::kDeadlineExceeded, "time budget exhausted");
}

}  // namespace k4reg
