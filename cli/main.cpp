// hemibake: one binary, sub-commands. Exit codes (CONVENTIONS.md): 0 success, 1 bad input or failed run, 2 bad
// command line. Every failure is one line on stderr; stdout carries results only.
#include <cstdio>
#include <exception>
#include <iostream>
#include <map>
#include <new>

#include "cli/command.h"
#include "cli/huge_page_heap.h"
#include "cli/stale_temporaries.h"
#include "mesh/errors.h"

int main(int argc, char** argv) {
    hemibake::cli::restartWithHugePageHeap(argv);
    CLI::App app{"hemibake: progressive hemicube radiosity lightmap baker (glTF in, lightmaps out)", "hemibake"};
    app.set_version_flag("--version", std::string("hemibake ") + HEMIBAKE_VERSION);
    app.require_subcommand(1);
    std::map<CLI::App*, hemibake::cli::CommandRunner> runners;
    auto add = [&](auto registerFn) {
        hemibake::cli::CommandRunner run = registerFn(app);
        runners[app.get_subcommands({}).back()] = std::move(run);
    };
    add(hemibake::cli::addInfoCommand);
    add(hemibake::cli::addBakeCommand);
    add(hemibake::cli::addReferenceCommand);
    add(hemibake::cli::addCompareCommand);
    add(hemibake::cli::addBatchCommand);
    add(hemibake::cli::addSampleVolumeCommand);
    add(hemibake::cli::addRenderCommand);

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "hemibake: " << e.what() << " (see --help)\n";
        return 2;
    }
    try {
        for (CLI::App* sub : app.get_subcommands())
            if (auto it = runners.find(sub); it != runners.end()) {
                // What a killed earlier run into the same output left (cli/stale_temporaries.h), before writing.
                hemibake::cli::removeStaleTemporaries(*sub);
                return it->second();
            }
        return 2;
    } catch (const hemibake::InputError& e) {
        std::cerr << "hemibake: " << e.what() << "\n";
        return 1;
    } catch (const std::bad_alloc&) {
        std::cerr << "hemibake: out of memory\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "hemibake: " << e.what() << "\n";
        return 1;
    }
}
