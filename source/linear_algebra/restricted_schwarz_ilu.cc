#include <deal.II/base/exceptions.h>

#include <immersed_grains/linear_algebra/restricted_schwarz_ilu.h>

#include <Ifpack.h>
#include <Ifpack_Preconditioner.h>
#include <Teuchos_ParameterList.hpp>

namespace ImmersedGrains
{
  void
  RestrictedSchwarzILU::initialize(
    const dealii::TrilinosWrappers::SparseMatrix &matrix,
    const unsigned int                            overlap)
  {
    preconditioner.reset();
    Ifpack_Preconditioner *ilu =
      Ifpack().Create("ILU",
                      const_cast<Epetra_CrsMatrix *>(&matrix.trilinos_matrix()),
                      overlap);
    AssertThrow(ilu != nullptr,
                dealii::ExcMessage("Ifpack could not create its ILU."));
    preconditioner = Teuchos::rcp(ilu);

    Teuchos::ParameterList parameters;
    parameters.set("fact: level-of-fill", 0);
    parameters.set("fact: absolute threshold", 0.);
    parameters.set("fact: relative threshold", 1.);
    parameters.set("schwarz: combine mode", "Zero");
    int error = ilu->SetParameters(parameters);
    AssertThrow(error == 0, dealii::LACExceptions::ExcTrilinosError(error));
    error = ilu->Initialize();
    AssertThrow(error == 0, dealii::LACExceptions::ExcTrilinosError(error));
    error = ilu->Compute();
    AssertThrow(error == 0, dealii::LACExceptions::ExcTrilinosError(error));
  }
} // namespace ImmersedGrains
