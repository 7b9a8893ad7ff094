#include "safecass/filters/registry.hpp"

namespace safecass {

[[nodiscard]] Expected<std::vector<std::size_t>> scalar_shape(const FilterManifest& manifest,
                                                              const FilterShape& shape) {
  for (const Signal* s : shape.inputs) {
    if (s->size() != 1) {
      return fail(ErrorCode::InvalidArgument, "filter '" + shape.filter + "' (" + manifest.type + "): input '" +
                                                  s->name() + "' has size " + std::to_string(s->size()) + "; " +
                                                  manifest.type + " needs a scalar (use Norm for vectors)");
    }
  }
  return std::vector<std::size_t>(manifest.outputs.size(), 1);
}

Expected<void> FilterRegistry::add(std::string type, FilterManifest manifest, FilterFactory factory, ShapeCheck shape) {
  if (find(type) != nullptr) return fail(ErrorCode::Duplicate, "filter type '" + type + "' is already registered");
  manifest.type = type;
  auto entry = std::make_unique<Entry>();
  entry->manifest = std::move(manifest);
  entry->factory = std::move(factory);
  if (shape) {
    entry->shape = std::move(shape);
  } else {
    entry->shape = [m = entry->manifest](const FilterShape& s) { return scalar_shape(m, s); };
  }
  entries_.emplace_back(std::move(type), std::move(entry));
  return {};
}

Expected<void> FilterRegistry::alias(std::string alias, std::string type) {
  if (find(alias) != nullptr) return fail(ErrorCode::Duplicate, "filter type '" + alias + "' is already registered");
  if (find(type) == nullptr) return fail(ErrorCode::NotFound, "alias '" + alias + "': no filter type '" + type + "'");
  aliases_.emplace_back(std::move(alias), std::move(type));
  return {};
}

const FilterRegistry::Entry* FilterRegistry::find(std::string_view type) const noexcept {
  for (const auto& [name, entry] : entries_) {
    if (name == type) return entry.get();
  }
  for (const auto& [alias, target] : aliases_) {
    if (alias == type) return find(target);
  }
  return nullptr;
}

std::vector<const FilterManifest*> FilterRegistry::manifests() const {
  std::vector<const FilterManifest*> out;
  for (const auto& [name, entry] : entries_) out.push_back(&entry->manifest);
  return out;
}

}  // namespace safecass
