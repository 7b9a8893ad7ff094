#!/usr/bin/env bash
# scripts/lint-surface.py on samples: a class with one public member function more than the limit
# fails and is named; constructors, the destructor, deleted functions, assignment, type aliases,
# data members, private and protected members and calls inside inline bodies are not counted,
# overloads are. Then the coordinator itself is within its limit.
set -euo pipefail
script=$1 source=$2 work=$3
mkdir -p "$work"
cat >"$work/sample.hpp" <<'CPP'
class Other {
public:
  void not_this_one();
};
class Sample {
public:
  explicit Sample(int a);
  ~Sample();
  Sample(const Sample&) = delete;
  Sample& operator=(const Sample&) = delete;
  using Id = int;
  // void in_a_comment();
  int size() const noexcept { return count(1) + count(2); }
  [[nodiscard]] int find(const char* name) const;
  int find(int id) const;
  template <class F>
  void each(F&& f) const {
    for (int i = 0; i < size(); ++i) f(i);
  }
  const char* text = "void in_a_string();";
  struct Inner {
    void inner_member();
  };

protected:
  void hidden();

private:
  int count(int x) const;
  int value_ = 0;
};
CPP
set +e
out=$(python3 "$script" "$work/sample.hpp" Sample 3)
rc=$?
set -e
echo "$out"
[ "$rc" -eq 1 ] || { echo "FAIL: exit code $rc, not 1, with 4 public member functions over a limit of 3"; exit 1; }
grep -q "Sample has 4 public member functions (at most 3): size find find each$" <<<"$out" ||
  { echo "FAIL: the count or the names are wrong"; exit 1; }
python3 "$script" "$work/sample.hpp" Sample 4 >/dev/null || { echo "FAIL: 4 public member functions fail a limit of 4"; exit 1; }
python3 "$script" "$source/core/include/safecass/core/coordinator.hpp" Coordinator 35 ||
  { echo "FAIL: the coordinator has more than 35 public member functions"; exit 1; }
echo PASS
