// A source for the targets that own the precompiled headers (cmake/CairnTargets.cmake).
namespace cairn {
int PchAnchor();
int PchAnchor() { return 0; }
}  // namespace cairn
