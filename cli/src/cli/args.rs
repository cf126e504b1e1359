//! The argument types several commands share: `--format` for a mesh on standard input or output
//! ([`StdioFormat`], [`FormatArg`]) and `--boundary` ([`BoundaryArg`], the boundary handling of
//! the paper's section 3.3). The library knows nothing of clap: these name its types on the
//! command line and map onto them.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::ValueEnum;
use fairmesh::fairing::BoundaryMode;
use fairmesh::io::Format;

/// The format of a mesh read from standard input or written to standard output (`-`): one of
/// [`Format::ALL`], named on the command line by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FormatArg(pub Format);

/// Every [`Format`] as a [`FormatArg`], in [`Format::ALL`]'s order (the order `--help` lists).
const FORMAT_ARGS: [FormatArg; Format::ALL.len()] = {
    let mut args = [FormatArg(Format::Obj); Format::ALL.len()];
    let mut i = 0;
    while i < args.len() {
        args[i] = FormatArg(Format::ALL[i]);
        i += 1;
    }
    args
};

impl ValueEnum for FormatArg {
    fn value_variants<'a>() -> &'a [Self] {
        &FORMAT_ARGS
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.0.extension()))
    }
}

impl From<FormatArg> for Format {
    fn from(format: FormatArg) -> Self {
        format.0
    }
}

/// `--format`, for the commands that read or write one mesh.
#[derive(clap::Args, Debug, Clone, Copy, Default)]
pub struct StdioFormat {
    /// Format of the mesh read from standard input or written to standard output, where the
    /// input or the output is `-` (files are known by their extension).
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
}

/// `--boundary`: how boundary vertices of open meshes move.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum BoundaryArg {
    /// Smooth each boundary loop as a curve (paper section 3.3).
    Curve,
    /// Keep boundary vertices where they are.
    Fixed,
}

impl BoundaryArg {
    /// The parser of a `--boundary` whose help lists the values by name only, without what each
    /// does (`multires --boundary`; `fair --boundary` lists both).
    pub fn names_only_parser() -> impl TypedValueParser<Value = BoundaryArg> {
        PossibleValuesParser::new(Self::value_variants().iter().filter_map(|value| {
            value
                .to_possible_value()
                .map(|possible| possible.help(None))
        }))
        .map(|name| {
            Self::from_str(&name, false).expect("the parser accepts only BoundaryArg's names")
        })
    }
}

impl From<BoundaryArg> for BoundaryMode {
    fn from(boundary: BoundaryArg) -> Self {
        match boundary {
            BoundaryArg::Curve => BoundaryMode::Curve,
            BoundaryArg::Fixed => BoundaryMode::Fixed,
        }
    }
}
