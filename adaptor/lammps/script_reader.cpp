#include "script_reader.h"

#include <sstream>

namespace lantern_lammps {
namespace {

size_t count_triple_quotes(const std::string &line) {
  size_t n = 0;
  for (size_t at = line.find("\"\"\""); at != std::string::npos; at = line.find("\"\"\"", at + 3))
    ++n;
  return n;
}

// The line's last printable character is '&': LAMMPS joins the next line to it.
bool continues(std::string *line) {
  const size_t last = line->find_last_not_of(" \t\r\n");
  if (last == std::string::npos || (*line)[last] != '&') return false;
  line->erase(last);
  return true;
}

bool blank(const std::string &command) {
  return command_words(command).empty();
}

}  // namespace

std::vector<ScriptCommand> split_commands(const std::string &script) {
  std::vector<ScriptCommand> out;
  std::istringstream in(script);
  std::string line, command;
  int number = 0, start = 0;
  bool in_triple = false;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (command.empty() && !in_triple) start = number;
    if (count_triple_quotes(line) % 2 == 1) in_triple = !in_triple;
    if (in_triple) {  // inside """...""": the newline is part of the argument
      command += line + "\n";
      continue;
    }
    const bool more = continues(&line);
    command += line;
    if (more) {
      command += " ";
      continue;
    }
    if (!blank(command)) out.push_back({command, start});
    command.clear();
  }
  if (!command.empty() && !blank(command)) out.push_back({command, start});
  return out;
}

std::vector<std::string> command_words(const std::string &command) {
  std::vector<std::string> words;
  std::string word;
  char quote = 0;
  for (const char c : command) {
    if (quote) {
      word += c;
      if (c == quote) quote = 0;
      continue;
    }
    if (c == '#') break;  // a comment runs to the end of the command
    if (c == '"' || c == '\'') {
      quote = c;
      word += c;
    } else if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
      if (!word.empty()) words.push_back(word), word.clear();
    } else {
      word += c;
    }
  }
  if (!word.empty()) words.push_back(word);
  return words;
}

}  // namespace lantern_lammps
