//! A plugin's parameters, each marked when the importer reads it, so that whatever it does not
//! read is refused by name and place instead of being silently ignored.

use std::cell::RefCell;

use super::values::number;
use super::xml::{Element, ImportError, error_at};

/// The children of a plugin element, with a mark per child once read.
pub(crate) struct Params<'a> {
    pub(crate) el: &'a Element,
    used: RefCell<Vec<bool>>,
}

impl<'a> Params<'a> {
    /// The parameters of `el`, none read yet.
    pub(crate) fn new(el: &'a Element) -> Self {
        Self { el, used: RefCell::new(vec![false; el.children.len()]) }
    }

    /// The child named `name`, marked as read.
    pub(crate) fn get(&self, name: &str) -> Option<&'a Element> {
        let i = self.el.children.iter().position(|c| c.attr("name") == Some(name))?;
        self.used.borrow_mut()[i] = true;
        Some(&self.el.children[i])
    }

    /// The number `name` (`<float>` or `<integer>`), or `default`.
    pub(crate) fn float(&self, name: &str, default: f64) -> Result<f64, ImportError> {
        self.get(name).map_or(Ok(default), number)
    }

    /// The string `name`, if given.
    pub(crate) fn string(&self, name: &str) -> Result<Option<&'a str>, ImportError> {
        self.get(name).map(|c| c.required("value")).transpose()
    }

    /// The boolean `name`, or `default`.
    pub(crate) fn boolean(&self, name: &str, default: bool) -> Result<bool, ImportError> {
        match self.get(name) {
            None => Ok(default),
            Some(c) => match c.required("value")? {
                "true" | "1" => Ok(true),
                "false" | "0" => Ok(false),
                v => Err(error_at(&c.loc, format!("{}: `{v}` is not true or false", c.describe()))),
            },
        }
    }

    /// The unnamed children with tag `tag` (nested plugins and `<ref>`s), marked as read.
    pub(crate) fn nested(&self, tag: &str) -> Vec<&'a Element> {
        let mut used = self.used.borrow_mut();
        self.el
            .children
            .iter()
            .enumerate()
            .filter(|(_, c)| c.tag == tag)
            .map(|(i, c)| {
                used[i] = true;
                c
            })
            .collect()
    }

    /// Refuses the first child that was not read: a parameter or nested element the importer
    /// does not support.
    pub(crate) fn finish(self) -> Result<(), ImportError> {
        let used = self.used.into_inner();
        match self.el.children.iter().zip(used).find(|(_, u)| !u) {
            None => Ok(()),
            Some((c, _)) => Err(error_at(
                &c.loc,
                format!(
                    "{} of {} is not supported (docs/import.md lists what is)",
                    c.describe(),
                    self.el.describe()
                ),
            )),
        }
    }
}
