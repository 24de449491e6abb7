#pragma once
// The `cairn` command-line tool: one binary, many subcommands. Each subcommand lives in its own
// file as `int RunXxx(const CommandArgs&)` and is listed once in cairn_main.cc.

#include <span>
#include <string>
#include <string_view>

namespace cairn::tools {

struct CommandArgs {
  std::string_view command;           // e.g. "bench stereo"
  std::span<char* const> args;        // what follows the command words
};

struct Command {
  std::string_view name;     // one or two words
  std::string_view summary;  // one line for `cairn help`
  int (*run)(const CommandArgs& args);
};

}  // namespace cairn::tools
