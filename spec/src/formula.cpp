// The invariant grammar of formula.hpp: a recursive-descent parser with byte offsets for errors.

#include "safecass/spec/formula.hpp"

#include <cctype>

namespace safecass::spec {

namespace {

constexpr int kMaxDepth = 64;

class Parser {
public:
  explicit Parser(std::string_view text) : text_(text) {}

  [[nodiscard]] tl::expected<Formula, FormulaError> run() {
    Formula f = equiv();
    if (!error_.message.empty()) return tl::unexpected(error_);
    skip();
    if (pos_ < text_.size()) {
      return tl::unexpected(FormulaError{"unexpected " + describe() + " after the end of the formula", pos_});
    }
    return f;
  }

private:
  void skip() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  bool peek(std::string_view token) {
    skip();
    return text_.substr(pos_, token.size()) == token;
  }
  bool take(std::string_view token) {
    if (!peek(token)) return false;
    pos_ += token.size();
    return true;
  }
  bool failed() const { return !error_.message.empty(); }
  Formula fail(std::string message) {
    if (!failed()) error_ = FormulaError{std::move(message), pos_};
    return Formula{};
  }
  std::string describe() {
    skip();
    if (pos_ >= text_.size()) return "end of formula";
    std::size_t n = 1;
    const std::string_view ops = "-<>=!|&[]";
    if (ops.find(text_[pos_]) != std::string_view::npos) {
      while (n < 3 && pos_ + n < text_.size() && ops.find(text_[pos_ + n]) != std::string_view::npos) ++n;
    }
    if (std::isalnum(static_cast<unsigned char>(text_[pos_])) != 0 || text_[pos_] == '_') {
      while (pos_ + n < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[pos_ + n])) != 0 ||
                                         text_[pos_ + n] == '_' || text_[pos_ + n] == '.' || text_[pos_ + n] == '-')) {
        ++n;
      }
    }
    return "'" + std::string(text_.substr(pos_, n)) + "'";
  }
  static Formula binary(Formula::Kind kind, Formula a, Formula b, std::size_t offset) {
    Formula f;
    f.kind = kind;
    f.offset = offset;
    f.operands.push_back(std::move(a));
    f.operands.push_back(std::move(b));
    return f;
  }

  Formula equiv() {
    Formula left = implies();
    while (!failed() && peek("<->")) {
      const std::size_t at = pos_;
      pos_ += 3;
      left = binary(Formula::Kind::Equiv, std::move(left), implies(), at);
    }
    return left;
  }
  Formula implies() {
    Formula left = disjunction();
    if (!failed() && peek("->")) {
      const std::size_t at = pos_;
      pos_ += 2;
      return binary(Formula::Kind::Implies, std::move(left), implies(), at);
    }
    return left;
  }
  Formula disjunction() {
    Formula left = conjunction();
    while (!failed() && peek("||")) {
      const std::size_t at = pos_;
      pos_ += 2;
      left = binary(Formula::Kind::Or, std::move(left), conjunction(), at);
    }
    return left;
  }
  Formula conjunction() {
    Formula left = until();
    while (!failed() && peek("&&")) {
      const std::size_t at = pos_;
      pos_ += 2;
      left = binary(Formula::Kind::And, std::move(left), until(), at);
    }
    return left;
  }
  Formula until() {
    Formula left = unary();
    skip();
    if (!failed() && pos_ < text_.size() && text_[pos_] == 'U' &&
        (pos_ + 1 == text_.size() ||
         !(std::isalnum(static_cast<unsigned char>(text_[pos_ + 1])) != 0 || text_[pos_ + 1] == '_'))) {
      const std::size_t at = pos_;
      ++pos_;
      return binary(Formula::Kind::Until, std::move(left), unary(), at);
    }
    return left;
  }
  Formula unary() {
    if (++depth_ > kMaxDepth) return fail("formula nested deeper than " + std::to_string(kMaxDepth) + " levels");
    Formula f = unary_inner();
    --depth_;
    return f;
  }
  Formula unary_inner() {
    skip();
    const std::size_t at = pos_;
    const auto prefix = [&](Formula::Kind kind) {
      Formula f;
      f.kind = kind;
      f.offset = at;
      f.operands.push_back(unary());
      return f;
    };
    if (take("!")) return prefix(Formula::Kind::Not);
    if (take("[]")) return prefix(Formula::Kind::Always);
    if (take("<>")) return prefix(Formula::Kind::Eventually);
    if (take("(")) {
      Formula f = equiv();
      if (failed()) return f;
      if (!take(")"))
        return fail("expected ')' to close the '(' at character " + std::to_string(at + 1) + ", found " + describe());
      return f;
    }
    if (pos_ >= text_.size())
      return fail("the formula ends where an address, '(' or an operator ([], <>, !) was expected");
    const std::string word = name();
    if (word.empty()) return fail("expected an address, '(' or an operator ([], <>, !), found " + describe());
    if (word == "true" || word == "false") {
      Formula f;
      f.kind = word == "true" ? Formula::Kind::True : Formula::Kind::False;
      f.offset = at;
      return f;
    }
    Formula atom;
    atom.kind = Formula::Kind::Atom;
    atom.address = word;
    atom.offset = at;
    skip();
    static constexpr std::pair<std::string_view, Formula::Compare> kOps[] = {
        {"==", Formula::Compare::Eq}, {"!=", Formula::Compare::Ne}, {"<=", Formula::Compare::Le},
        {">=", Formula::Compare::Ge}, {"<", Formula::Compare::Lt},  {">", Formula::Compare::Gt}};
    bool found = false;
    for (const auto& [text, op] : kOps) {
      // '<' must not be the start of '<>' or '<->'.
      if (text == "<" && (peek("<>") || peek("<-"))) continue;
      if (take(text)) {
        atom.compare = op;
        found = true;
        break;
      }
    }
    if (!found) {
      return fail("expected a comparison (==, !=, <, <=, >, >=) after address '" + word + "', found " + describe());
    }
    skip();
    const std::size_t level_at = pos_;
    const std::string level = name();
    const auto s = parse_state(level);
    if (!s) {
      pos_ = level_at;
      return fail("expected a level (Normal, Warning or Error) after '" + word + " " +
                  std::string(to_string(atom.compare)) + "', found " + describe());
    }
    atom.level = *s;
    return atom;
  }
  /// An address or a word: letters, digits, '_', '.', '-'.
  std::string name() {
    skip();
    const std::size_t start = pos_;
    while (pos_ < text_.size()) {
      const unsigned char c = static_cast<unsigned char>(text_[pos_]);
      const bool dash = c == '-' && !(pos_ + 1 < text_.size() && text_[pos_ + 1] == '>');
      if (std::isalnum(c) == 0 && c != '_' && c != '.' && !dash) break;
      ++pos_;
    }
    // A lone 'U' is the until operator, not a name.
    if (pos_ - start == 1 && text_[start] == 'U') pos_ = start;
    return std::string(text_.substr(start, pos_ - start));
  }

  std::string_view text_;
  std::size_t pos_ = 0;
  int depth_ = 0;
  FormulaError error_;
};

bool temporal(Formula::Kind k) {
  return k == Formula::Kind::Always || k == Formula::Kind::Eventually || k == Formula::Kind::Until;
}

}  // namespace

bool Formula::is_propositional() const {
  if (temporal(kind)) return false;
  for (const Formula& f : operands) {
    if (!f.is_propositional()) return false;
  }
  return true;
}

bool Formula::is_state_invariant() const {
  return kind == Kind::Always && operands.size() == 1 && operands[0].is_propositional();
}

void Formula::atoms(std::vector<const Formula*>& out) const {
  if (kind == Kind::Atom) out.push_back(this);
  for (const Formula& f : operands) f.atoms(out);
}

[[nodiscard]] tl::expected<Formula, FormulaError> parse_formula(std::string_view text) { return Parser(text).run(); }

std::string_view to_string(Formula::Compare c) noexcept {
  switch (c) {
    case Formula::Compare::Eq: return "==";
    case Formula::Compare::Ne: return "!=";
    case Formula::Compare::Lt: return "<";
    case Formula::Compare::Le: return "<=";
    case Formula::Compare::Gt: return ">";
    case Formula::Compare::Ge: return ">=";
  }
  return "==";
}

bool holds(Formula::Compare c, State state, State level) noexcept {
  switch (c) {
    case Formula::Compare::Eq: return state == level;
    case Formula::Compare::Ne: return state != level;
    case Formula::Compare::Lt: return state < level;
    case Formula::Compare::Le: return state <= level;
    case Formula::Compare::Gt: return state > level;
    case Formula::Compare::Ge: return state >= level;
  }
  return false;
}

std::string to_string(const Formula& f) {
  const auto bin = [&](const char* op) {
    return "(" + to_string(f.operands[0]) + " " + op + " " + to_string(f.operands[1]) + ")";
  };
  switch (f.kind) {
    case Formula::Kind::True: return "true";
    case Formula::Kind::False: return "false";
    case Formula::Kind::Atom:
      return f.address + " " + std::string(to_string(f.compare)) + " " + std::string(to_string(f.level));
    case Formula::Kind::Not: return "!" + to_string(f.operands[0]);
    case Formula::Kind::Always: return "[]" + to_string(f.operands[0]);
    case Formula::Kind::Eventually: return "<>" + to_string(f.operands[0]);
    case Formula::Kind::And: return bin("&&");
    case Formula::Kind::Or: return bin("||");
    case Formula::Kind::Implies: return bin("->");
    case Formula::Kind::Equiv: return bin("<->");
    case Formula::Kind::Until: return bin("U");
  }
  return "true";
}

}  // namespace safecass::spec
