//! The configured parts of a family of kinds (the generic components, the sensors), in registry
//! order then file order, behind one trait object: one list type for every family.
//!
//! A family implements [`ListEntry`] for its trait object (`dyn ComponentSpec`,
//! `dyn SensorSpec`; with [`list_entry`] when its trait has the usual methods) and names the
//! list (`type Components = KindList<dyn ComponentSpec>`).

use std::any::Any;

/// What [`KindList`] needs of a family's trait object.
pub trait ListEntry: 'static {
    /// The family's registry entry (one static value per kind).
    type Kind: 'static;
    /// This part's kind.
    fn entry_kind(&self) -> &'static Self::Kind;
    /// The configuration array of its kind (`thrusters`, `magnetometers`).
    fn config_array(&self) -> &'static str;
    /// A boxed copy.
    fn entry_clone(&self) -> Box<Self>;
    /// Whether `other` is the same kind with equal parameters.
    fn entry_eq(&self, other: &Self) -> bool;
    /// For typed access ([`KindList::of`]).
    fn entry_any(&self) -> &dyn Any;
    /// For typed access ([`KindList::of_mut`]).
    fn entry_any_mut(&mut self) -> &mut dyn Any;
}

/// The configured parts of one family, grouped by kind in registry order and in file order
/// within a kind.
#[derive(Debug)]
pub struct KindList<T: ?Sized + ListEntry> {
    items: Vec<Box<T>>,
}

impl<T: ?Sized + ListEntry> Default for KindList<T> {
    fn default() -> Self {
        Self { items: Vec::new() }
    }
}

impl<T: ?Sized + ListEntry> Clone for KindList<T> {
    fn clone(&self) -> Self {
        Self {
            items: self.items.iter().map(|c| c.entry_clone()).collect(),
        }
    }
}

impl<T: ?Sized + ListEntry> PartialEq for KindList<T> {
    fn eq(&self, other: &Self) -> bool {
        self.items.len() == other.items.len()
            && self
                .items
                .iter()
                .zip(&other.items)
                .all(|(a, b)| a.entry_eq(b))
    }
}

impl<T: ?Sized + ListEntry> KindList<T> {
    /// The list as given (the caller keeps registry order, then file order).
    pub fn new(items: Vec<Box<T>>) -> Self {
        Self { items }
    }

    /// Every part, in list order.
    pub fn iter(&self) -> impl Iterator<Item = &T> {
        self.items.iter().map(|c| c.as_ref())
    }

    /// Each part with its configuration path (`thrusters[1]`: its index within its kind).
    pub fn with_paths(&self) -> impl Iterator<Item = (String, &T)> {
        let mut index_in_kind = 0;
        let mut last: Option<&'static str> = None;
        self.items.iter().map(move |c| {
            let array = c.config_array();
            if last != Some(array) {
                last = Some(array);
                index_in_kind = 0;
            }
            let path = format!("{array}[{index_in_kind}]");
            index_in_kind += 1;
            (path, c.as_ref())
        })
    }

    /// The parts of type `P`, in file order.
    pub fn of<P: Any>(&self) -> impl Iterator<Item = &P> {
        self.items
            .iter()
            .filter_map(|c| c.entry_any().downcast_ref::<P>())
    }

    /// The parts of type `P`, in file order, collected.
    pub fn all<P: Any>(&self) -> Vec<&P> {
        self.of().collect()
    }

    /// The parts of type `P`, mutable (tests and campaigns that edit a built config).
    pub fn of_mut<P: Any>(&mut self) -> impl Iterator<Item = &mut P> {
        self.items
            .iter_mut()
            .filter_map(|c| c.entry_any_mut().downcast_mut::<P>())
    }

    /// How many parts of `kind` there are.
    pub fn count(&self, kind: &T::Kind) -> usize {
        self.items
            .iter()
            .filter(|c| std::ptr::eq(c.entry_kind(), kind))
            .count()
    }

    /// Number of parts.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }
}

/// `impl ListEntry for dyn Family` for a family trait with the usual methods (`kind`,
/// `box_clone`, `same_as`, `as_any`, `as_any_mut`), whose kind's configuration array is the
/// field `$array` of its registry entry.
#[macro_export]
macro_rules! list_entry {
    ($family:ty, $kind:ty, $array:ident) => {
        impl $crate::schema::kind_list::ListEntry for $family {
            type Kind = $kind;
            fn entry_kind(&self) -> &'static $kind {
                self.kind()
            }
            fn config_array(&self) -> &'static str {
                self.kind().$array
            }
            fn entry_clone(&self) -> Box<Self> {
                self.box_clone()
            }
            fn entry_eq(&self, other: &Self) -> bool {
                self.same_as(other)
            }
            fn entry_any(&self) -> &dyn std::any::Any {
                self.as_any()
            }
            fn entry_any_mut(&mut self) -> &mut dyn std::any::Any {
                self.as_any_mut()
            }
        }
    };
}
pub use crate::list_entry;
