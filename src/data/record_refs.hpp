// ctid internal — the records of a fit as the caller gave them (one IdData or a vector of them), without copying.
#pragma once

#include <vector>

#include "ctid/data/iddata.hpp"

namespace ctid::internal {

/// The records of a fit as the caller gave them — one record or several — without copying them (a fit of one
/// record does not copy it into a vector of one). Lives no longer than what it was made from.
class RecordRefs {
 public:
  RecordRefs(const IdData& d) : p_{&d} {}  // NOLINT(google-explicit-constructor): either form of the public calls
  RecordRefs(const std::vector<IdData>& ds) {  // NOLINT(google-explicit-constructor)
    for (const IdData& d : ds) p_.push_back(&d);
  }
  std::size_t size() const { return p_.size(); }
  bool empty() const { return p_.empty(); }
  const IdData& operator[](std::size_t i) const { return *p_[i]; }
  const IdData& front() const { return *p_.front(); }
  struct iterator {
    std::vector<const IdData*>::const_iterator at;
    const IdData& operator*() const { return **at; }
    iterator& operator++() {
      ++at;
      return *this;
    }
    bool operator!=(const iterator& o) const { return at != o.at; }
  };
  iterator begin() const { return {p_.begin()}; }
  iterator end() const { return {p_.end()}; }

 private:
  std::vector<const IdData*> p_;
};

}  // namespace ctid::internal
