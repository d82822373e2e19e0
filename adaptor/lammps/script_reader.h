// A LAMMPS input script cut into the commands LAMMPS would execute one by one.
//
// lantern-lammps hands LAMMPS one command at a time (lammps_command) so that it can attach to a
// `fix external` as soon as it is defined and check the script before every run. This reads the
// text as LAMMPS's own reader does: a line whose last printable character is '&' continues on the
// next line, and a triple-quoted ("""...""") argument may span lines. Comments and variables are
// left in the text: LAMMPS strips and substitutes them when it executes the command.
//
// Thread-safety: pure functions. Ownership: returns values.
#pragma once

#include <string>
#include <vector>

namespace lantern_lammps {

struct ScriptCommand {
  std::string text;  // the whole command, continuation lines joined with a space
  int line = 0;      // 1-based line of the script where it starts (for messages)
};

// Cuts `script` into commands; blank lines and comment-only lines are dropped.
std::vector<ScriptCommand> split_commands(const std::string &script);

// The words of a command as LAMMPS splits them, for lantern-lammps's own look at it: the comment
// (from a '#' outside quotes) removed, whitespace-separated, quotes kept as written.
std::vector<std::string> command_words(const std::string &command);

}  // namespace lantern_lammps
