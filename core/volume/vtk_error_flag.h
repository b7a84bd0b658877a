// SPDX-License-Identifier: AGPL-3.0-or-later
// Records that a VTK algorithm reported an error. Observing ErrorEvent also
// keeps VTK from printing the message: reader messages may quote header text.
#pragma once

#include <vtkCommand.h>

namespace labelmesh {

class VtkErrorFlag : public vtkCommand {
 public:
  static VtkErrorFlag* New() { return new VtkErrorFlag; }
  void Execute(vtkObject*, unsigned long, void*) override { raised = true; }
  bool raised = false;
};

}  // namespace labelmesh
