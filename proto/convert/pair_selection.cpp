#include "pair_selection.h"

#include <string>

#include "k4reg/util/error.h"

namespace k4reg::api {

v1::PairSelection pair_selection_to_proto(PairSelection selection) {
  switch (selection) {
    case PairSelection::kAll: return v1::PAIR_SELECTION_ALL;
    case PairSelection::kSequence: return v1::PAIR_SELECTION_SEQUENCE;
    case PairSelection::kList: return v1::PAIR_SELECTION_LIST;
    case PairSelection::kScreened: return v1::PAIR_SELECTION_SCREENED;
    case PairSelection::kAuto: return v1::PAIR_SELECTION_AUTO;
  }
  return v1::PAIR_SELECTION_UNSPECIFIED;
}

PairSelection pair_selection_from_proto(int selection) {
  switch (selection) {
    case v1::PAIR_SELECTION_UNSPECIFIED:
    case v1::PAIR_SELECTION_AUTO: return PairSelection::kAuto;
    case v1::PAIR_SELECTION_ALL: return PairSelection::kAll;
    case v1::PAIR_SELECTION_SEQUENCE: return PairSelection::kSequence;
    case v1::PAIR_SELECTION_LIST: return PairSelection::kList;
    case v1::PAIR_SELECTION_SCREENED: return PairSelection::kScreened;
    default: fail(ErrorCode::kInvalidArgument, "params.pairs: unknown value " + std::to_string(selection));
  }
}

}  // namespace k4reg::api
