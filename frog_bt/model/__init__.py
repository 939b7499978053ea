"""Pure types: keys, readings, enums, goals, the wires' and the recording's Structs."""
