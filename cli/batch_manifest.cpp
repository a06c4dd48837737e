#include "cli/batch_manifest.h"

#include <fstream>
#include <set>
#include <stdexcept>

#include "mesh/errors.h"

namespace hemibake::cli {

namespace {

namespace fs = std::filesystem;

// Options the batch itself decides for every scene; a manifest may not set them.
const std::set<std::string> kReserved = {"scene", "o", "output", "progress", "help", "h"};

std::string scalarArgument(const nlohmann::json& v) {
    if (v.is_string()) return v.get<std::string>();
    if (v.is_number()) return v.dump();  // shortest text that reads back as the same double
    throw std::invalid_argument("expected a number or a string, got " + v.dump());
}

void checkSettings(const fs::path& manifest, const std::string& where, const nlohmann::json& settings) {
    if (!settings.is_object()) throw InputError(manifest.string(), where + " must be an object of bake options");
    for (const auto& [key, value] : settings.items()) {
        if (kReserved.count(key))
            throw InputError(manifest.string(), where + " sets '" + key + "', which the batch decides for every scene");
        if (key.empty() || key.front() == '-')
            throw InputError(manifest.string(), where + " has option '" + key + "': write bake option names without dashes");
        try {
            bakeArguments(nlohmann::json{{key, value}});
        } catch (const std::invalid_argument& e) {
            throw InputError(manifest.string(), where + " option '" + key + "': " + e.what());
        }
    }
}

}  // namespace

std::vector<std::string> bakeArguments(const nlohmann::json& settings) {
    std::vector<std::string> args;
    for (const auto& [key, value] : settings.items()) {
        if (value.is_boolean()) {
            if (value.get<bool>()) args.push_back("--" + key);  // a flag; false leaves the bake's default
            continue;
        }
        std::string text;
        if (value.is_array()) {
            for (const auto& element : value) text += (text.empty() ? "" : ",") + scalarArgument(element);
            if (value.empty()) throw std::invalid_argument("empty list");
        } else {
            text = scalarArgument(value);
        }
        args.push_back("--" + key);
        args.push_back(text);
    }
    return args;
}

BatchManifest loadBatchManifest(const fs::path& path) {
    const std::string where = path.string();
    std::error_code ec;
    if (!fs::exists(path, ec)) throw InputError(where, "manifest not found");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(where, "cannot be opened for reading");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::parse_error& e) {
        throw InputError(where, std::string("not valid JSON: ") + e.what());
    }
    if (!j.is_object()) throw InputError(where, "a manifest is a JSON object with a \"scenes\" list");
    const nlohmann::json defaults = j.value("defaults", nlohmann::json::object());
    checkSettings(path, "\"defaults\"", defaults);
    if (!j.contains("scenes") || !j["scenes"].is_array()) throw InputError(where, "has no \"scenes\" list");

    BatchManifest m;
    m.path = path;
    const fs::path base = path.has_parent_path() ? path.parent_path() : fs::path(".");
    std::set<std::string> names;
    std::set<fs::path> outputs;
    for (std::size_t i = 0; i < j["scenes"].size(); ++i) {
        const nlohmann::json& e = j["scenes"][i];
        const std::string entry = "scene " + std::to_string(i);
        if (!e.is_object()) throw InputError(where, entry + " is not an object");
        if (!e.contains("scene") || !e["scene"].is_string() || e["scene"].get<std::string>().empty())
            throw InputError(where, entry + " has no \"scene\" path");
        if (!e.contains("output") || !e["output"].is_string() || e["output"].get<std::string>().empty())
            throw InputError(where, entry + " has no \"output\" directory");
        BatchScene s;
        s.index = i;
        s.scene = (base / e["scene"].get<std::string>()).lexically_normal();
        s.output = (base / e["output"].get<std::string>()).lexically_normal();
        if (s.output.filename().empty()) s.output = s.output.parent_path();  // "out/a/" → "out/a"
        s.name = e.contains("name") && e["name"].is_string() ? e["name"].get<std::string>() : s.scene.stem().string();
        const nlohmann::json own = e.value("settings", nlohmann::json::object());
        checkSettings(path, entry + " (" + s.name + ") \"settings\"", own);
        s.settings = defaults;
        s.settings.update(own);
        if (!names.insert(s.name).second)
            throw InputError(where, entry + ": the name '" + s.name + "' is used twice (give the scenes distinct \"name\"s)");
        if (!outputs.insert(fs::absolute(s.output).lexically_normal()).second)
            throw InputError(where, entry + " (" + s.name + "): output '" + s.output.string() + "' is used by another scene");
        m.scenes.push_back(std::move(s));
    }
    return m;
}

}  // namespace hemibake::cli
